// OBJ/MTL loading (src/scene/obj.cpp) on small files written by the tests: triangulation, negative
// indices, missing normals/UVs/MTL/textures, CRLF, usemtl per face, errors naming file and line,
// transforms (normals by the inverse transpose, mirroring keeps orientation) and the MTL mapping
// of docs/obj-mtl.md.
#include <gtest/gtest.h>
#include <stb/stb_image_write.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <glm/gtc/matrix_transform.hpp>
#include <iterator>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "lucent/error.hpp"
#include "scene/loaders.hpp"
#include "scene/obj_internal.hpp"
#include "support.hpp"

namespace test_obj {

namespace {

using lucent::Material;
using lucent::MaterialType;
using lucent::Scene;
using lucent::Triangle;

using lucent::test::CaptureWarnings;

void load(Scene& scene, const std::string& path, const glm::dmat4& xf = glm::dmat4(1.0),
          int material_override = -1, lucent::scene_detail::ObjMaterials* known = nullptr) {
  lucent::scene_detail::load_obj(scene, path, xf, material_override, known);
}

std::string write(const std::string& dir, const std::string& name, const std::string& text) {
  std::filesystem::create_directories(std::filesystem::path(dir + "/" + name).parent_path());
  lucent::test::write_file(dir + "/" + name, text);
  return dir + "/" + name;
}

/// An OBJ file `name` in `dir` that loads the library `mtllib` and gives each material of
/// `materials` one triangle, in order; its path.
std::string one_face_per_material(const std::string& dir, const std::string& name,
                                  const std::string& mtllib,
                                  const std::vector<const char*>& materials) {
  std::string obj = "mtllib " + mtllib + "\nv 0 0 0\nv 1 0 0\nv 1 1 0\n";
  for (const char* n : materials) obj += std::string("usemtl ") + n + "\nf 1 2 3\n";
  return write(dir, name, obj);
}

glm::dvec3 pos(const Scene& s, const Triangle& t, int k) { return s.positions[t.v[k]]; }
glm::dvec3 geometric_normal(const Scene& s, const Triangle& t) {
  return glm::cross(pos(s, t, 1) - pos(s, t, 0), pos(s, t, 2) - pos(s, t, 0));
}
double area(const Scene& s, const Triangle& t) { return 0.5 * glm::length(geometric_normal(s, t)); }

// The triangle's corners as a sorted list, to identify it whatever its vertex order.
std::array<std::array<double, 3>, 3> corners(const Scene& s, const Triangle& t) {
  std::array<std::array<double, 3>, 3> c;
  for (int k = 0; k < 3; ++k) c[k] = {pos(s, t, k).x, pos(s, t, k).y, pos(s, t, k).z};
  std::sort(c.begin(), c.end());
  return c;
}

// tinyobjloader reads numbers as float: compare colours to single precision
#define EXPECT_COLOUR(a, ...) EXPECT_NEAR(glm::length((a)-glm::dvec3(__VA_ARGS__)), 0.0, 1e-6) << #a
// `text` was warned once (a CaptureWarnings `w`)
#define EXPECT_WARNED_ONCE(w, text) EXPECT_EQ((w).count(text), 1) << (w).dump()

const Material& material_named(const Scene& s, const std::string& name) {
  int i = s.find_material(name);
  EXPECT_GE(i, 0) << "no material named " << name;
  static Material none;
  return i >= 0 ? s.materials[i] : none;
}

// Polygons keep their area and their winding in every triangle, concave ones included.
TEST(Obj, QuadsAndNgonsAreTriangulatedKeepingAreaAndOrientation) {
  std::string dir = lucent::test::temp_dir();
  std::string path = write(dir, "poly.obj",
                           "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\n"
                           "v 0 0 1\nv 2 0 1\nv 3 1 1\nv 1 2 1\nv -1 1 1\n"
                           "f 1 2 3 4\n"
                           "f 5 6 7 8 9\n"
                           // a concave L (area 3) starting at a vertex a fan would get wrong
                           "v 2 1 2\nv 1 1 2\nv 1 2 2\nv 0 2 2\nv 0 0 2\nv 2 0 2\n"
                           "f 10 11 12 13 14 15\n"
                           // an arrowhead quad (area 9), its reflex corner last, then first:
                           // tinyobjloader split it along its shorter diagonal, outside it (area
                           // 10 + 1 facing the other way)
                           "v 0 0 3\nv 10 1 3\nv 0 2 3\nv 1 1 3\nf 16 17 18 19\n"
                           "v 0 0 4\nv 10 1 4\nv 0 2 4\nv 1 1 4\nf 23 20 21 22\n"
                           // a pentagon with two reflex corners (area 6.5): tinyobjloader's ear
                           // clipping covered points outside it (11.5 in all)
                           "v 0 0 5\nv 5 1 5\nv 10 1 5\nv 0 2 5\nv 1 1 5\nf 24 25 26 27 28\n");
  CaptureWarnings w;
  Scene s;
  load(s, path);
  EXPECT_TRUE(w.all().empty()) << w.dump();
  ASSERT_EQ(s.triangles.size(), 2u + 3u + 4u + 2u + 2u + 3u);
  // the quad is 2 x 1, the pentagon 5 (shoelace), the L 3, the arrowheads 9, the last one 6.5
  double area_by_z[6] = {0, 0, 0, 0, 0, 0};
  for (const Triangle& t : s.triangles) {
    glm::dvec3 n = geometric_normal(s, t);
    EXPECT_GT(n.z, 0) << "counter-clockwise polygons face +z";
    area_by_z[static_cast<int>(pos(s, t, 0).z)] += area(s, t);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(t.n[k], -1);
      EXPECT_EQ(t.uv[k], -1);
    }
  }
  const double want[6] = {2.0, 5.0, 3.0, 9.0, 9.0, 6.5};
  for (int z = 0; z < 6; ++z) EXPECT_NEAR(area_by_z[z], want[z], 1e-9) << "z = " << z;
  // a polygon of no area (its corners on a line) cannot be ear-clipped: fanned, and said
  path = write(dir, "line.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nv 4 0 0\nf 1 2 3 4 5\n");
  Scene t;
  load(t, path);
  EXPECT_EQ(t.triangles.size(), 3u);
  EXPECT_EQ(w.count("polygon(s) that cut themselves or have no area were split as fans"), 1)
      << w.dump();
}

// "f 1 2 3 3" (a triangle written as a quad, as some exporters do) was fanned into a triangle and
// a degenerate one, with two warnings that did not fit it: "1 polygon(s) that cut themselves or
// have no area were split as fans" and, at render, "skipped 1 degenerate triangle(s)". Found by
// loading quads with a repeated corner. A corner at the position of the one before it is left
// out before the polygon is triangulated.
TEST(Obj, RepeatedCornersAreLeftOutWithoutAWarning) {
  std::string dir = lucent::test::temp_dir();
  std::string path = write(dir, "dup.obj",
                           "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n"
                           "f 1/1 2/2 3/3 3/3\n"  // a triangle (area 1)
                           "f 1 1 2 3 4\n"        // a quad (area 2)
                           "f 4 1 2 2 3 4\n"      // the quad, first and last corner the same
                           "f 1 2 3 4 1\n");      // and once more
  CaptureWarnings w;
  Scene s;
  load(s, path);
  EXPECT_TRUE(w.all().empty()) << w.dump();
  ASSERT_EQ(s.triangles.size(), 1u + 2u + 2u + 2u);
  EXPECT_NEAR(area(s, s.triangles[0]), 1.0, 1e-12);
  double total = 0;
  for (const Triangle& t : s.triangles) {
    EXPECT_GT(area(s, t), 0.5 - 1e-12);
    EXPECT_GT(geometric_normal(s, t).z, 0);
    total += area(s, t);
  }
  EXPECT_NEAR(total, 1.0 + 3 * 2.0, 1e-12);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(s.triangles[0].uv[k], k);
}

// A pentagram (corners 1 3 5 2 4 of a pentagon) has ears, so ear clipping ran to its end, and
// the last three corners, taken without a test, made a triangle facing the other way: the polygon
// cuts itself, but there was no warning, while docs/obj-mtl.md promises one for such polygons.
// Found by loading self-intersecting polygons. Now it is fanned and said, as when no ear is left.
TEST(Obj, SelfIntersectingPolygonsThatClipBackwardsAreFannedAndSaid) {
  std::string dir = lucent::test::temp_dir();
  std::string text;
  for (int k = 0; k < 5; ++k) {
    const double a = 2 * 3.14159265358979 * k / 5 + 3.14159265358979 / 2;
    text += "v " + std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + " 0\n";
  }
  std::string path = write(dir, "star.obj", text + "f 1 3 5 2 4\n");
  CaptureWarnings w;
  Scene s;
  load(s, path);
  EXPECT_EQ(s.triangles.size(), 3u);
  EXPECT_EQ(w.count("1 polygon(s) that cut themselves or have no area were split as fans"), 1)
      << w.dump();
  // fanned from its first corner
  for (size_t i = 0; i < s.triangles.size(); ++i) EXPECT_EQ(s.triangles[i].v[0], 0);
}

TEST(Obj, NegativeIndicesAreRelativeToTheVerticesSoFar) {
  std::string dir = lucent::test::temp_dir();
  std::string a = write(dir, "abs.obj",
                        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n"
                        "f 1/1 2/2 3/3\n"
                        "v 5 0 0\nv 6 0 0\nv 6 1 0\n"
                        "f 5/1 6/2 7/3\nf 1/1 3/3 4/2\n");
  std::string b = write(dir, "rel.obj",
                        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n"
                        "f -4/-3 -3/-2 -2/-1\n"
                        "v 5 0 0\nv 6 0 0\nv 6 1 0\n"
                        "f -3/-3 -2/-2 -1/-1\nf -7/-3 -5/-1 -4/-2\n");
  Scene sa, sb;
  load(sa, a);
  load(sb, b);
  ASSERT_EQ(sa.triangles.size(), 3u);
  ASSERT_EQ(sb.triangles.size(), 3u);
  std::multiset<std::vector<double>> ta, tb;
  for (auto* p : {&sa, &sb})
    for (const Triangle& t : p->triangles) {
      std::vector<double> key;
      for (int k = 0; k < 3; ++k) {
        glm::dvec3 v = pos(*p, t, k);
        glm::dvec2 uv = p->uvs[t.uv[k]];
        key.insert(key.end(), {v.x, v.y, v.z, uv.x, uv.y});
      }
      (p == &sa ? ta : tb).insert(key);
    }
  EXPECT_EQ(ta, tb);
}

TEST(Obj, MissingNormalsOrUvsArePerTriangle) {
  std::string dir = lucent::test::temp_dir();
  std::string path = write(dir, "mixed.obj",
                           "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                           "vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\n"
                           "f 1 2 3\n"
                           "f 1/1 2/2 4/3\n"
                           "f 2//1 3//1 4//1\n"
                           "f 1/1/1 3/3/1 4/2/1\n");
  Scene s;
  load(s, path);
  ASSERT_EQ(s.triangles.size(), 4u);
  std::map<std::array<std::array<double, 3>, 3>, const Triangle*> by_corners;
  for (const Triangle& t : s.triangles) by_corners[corners(s, t)] = &t;
  auto find = [&](glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) -> const Triangle& {
    std::array<std::array<double, 3>, 3> k = {{{a.x, a.y, a.z}, {b.x, b.y, b.z}, {c.x, c.y, c.z}}};
    std::sort(k.begin(), k.end());
    EXPECT_TRUE(by_corners.count(k));
    return *by_corners[k];
  };
  const Triangle& none = find({0, 0, 0}, {1, 0, 0}, {1, 1, 0});
  const Triangle& uv = find({0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  const Triangle& n = find({1, 0, 0}, {1, 1, 0}, {0, 1, 0});
  const Triangle& both = find({0, 0, 0}, {1, 1, 0}, {0, 1, 0});
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(none.n[k], -1);
    EXPECT_EQ(none.uv[k], -1);
    EXPECT_EQ(uv.n[k], -1);
    ASSERT_GE(uv.uv[k], 0);
    ASSERT_GE(n.n[k], 0);
    EXPECT_EQ(n.uv[k], -1);
    ASSERT_GE(both.n[k], 0);
    ASSERT_GE(both.uv[k], 0);
    EXPECT_EQ(s.normals[n.n[k]], glm::dvec3(0, 0, 1));
  }
  // each corner keeps its own uv: position (0,1,0) of the "uv" triangle has vt 3 = (1, 1)
  for (int k = 0; k < 3; ++k)
    if (pos(s, uv, k) == glm::dvec3(0, 1, 0)) {
      EXPECT_EQ(s.uvs[uv.uv[k]], glm::dvec2(1, 1));
    }
}

TEST(Obj, MissingMtlWarnsOnceAndUsesOneDefaultMaterial) {
  std::string dir = lucent::test::temp_dir();
  std::string path = write(dir, "nomtl.obj",
                           "mtllib nothere.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\n"
                           "usemtl paint\nf 1 2 3\nusemtl other\nf 1 3 2\n");
  CaptureWarnings w;
  Scene s;
  s.materials.push_back(Material{});         // a material of the scene's own, left alone
  lucent::scene_detail::ObjMaterials known;  // as SceneBuilder keeps them
  load(s, path, glm::dmat4(1.0), -1, &known);
  load(s, path, glm::dmat4(1.0), -1, &known);
  ASSERT_EQ(w.all().size(), 2u) << "one warning per load:\n" << w.dump();
  EXPECT_EQ(w.count("nothere.mtl"), 2) << w.dump();
  EXPECT_EQ(w.count(path), 2) << w.dump();
  ASSERT_EQ(s.triangles.size(), 4u);
  ASSERT_EQ(s.materials.size(), 2u) << "the default material is added once";
  const Material& d = s.materials[1];
  EXPECT_EQ(d.type, MaterialType::Diffuse);
  EXPECT_EQ(d.albedo, glm::dvec3(0.8));
  EXPECT_EQ(d.albedo_texture, -1);
  EXPECT_FALSE(d.emissive());
  for (const Triangle& t : s.triangles) EXPECT_EQ(t.material, 1);
}

// A UTF-8 byte-order mark (Notepad's, other Windows tools') is skipped: tinyobjloader read it as
// part of the first statement, which vanished without a word (a first vertex lost and every
// index shifted by one; a first mtllib or newmtl not read: the default material, with a warning
// that the file names no library).
TEST(Obj, AUtf8ByteOrderMarkIsSkipped) {
  const std::string dir = lucent::test::temp_dir(), bom = "\xEF\xBB\xBF";
  CaptureWarnings w;
  Scene s;
  // two at the start, and one at the start of a line (files joined with cat)
  load(s, write(dir, "v.obj",
                bom + bom + "v -1 -1 0\nv 1 -1 0\n" + bom + "v 0 1 0\nv 5 5 5\nf 1 2 3\n"));
  ASSERT_EQ(s.positions.size(), 4u);
  ASSERT_EQ(s.triangles.size(), 1u);
  EXPECT_EQ(pos(s, s.triangles[0], 0), glm::dvec3(-1, -1, 0));
  EXPECT_EQ(pos(s, s.triangles[0], 2), glm::dvec3(0, 1, 0));
  write(dir, "m.mtl", bom + "newmtl red\nKd 1 0 0\n");
  Scene m;
  load(m,
       write(dir, "m.obj", bom + "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n"));
  EXPECT_TRUE(w.all().empty()) << w.dump();
  EXPECT_COLOUR(material_named(m, "m.obj:red").albedo, 1, 0, 0);
}

// One library of several not found: only the materials it would define are lost, and a usemtl
// that no library read defines still warns (the warning said every face used the default
// material while the others had theirs, and such usemtl names went unsaid). A library that is a
// symbolic link loop is unreadable, not "not found".
TEST(Obj, ALibraryNotFoundBesideOthersLosesOnlyItsMaterials) {
  const std::string dir = lucent::test::temp_dir();
  write(dir, "m.mtl", "newmtl red\nKd 1 0 0\n");
  const std::string path = write(dir, "x.obj",
                                 "mtllib nothere.mtl m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                 "usemtl red\nf 1 2 3\nusemtl blue\nf 1 3 2\n"
                                 "usemtl green\nf 2 1 3\n");
  CaptureWarnings w;
  Scene s;
  load(s, path);
  EXPECT_WARNED_ONCE(w, path + ": material library 'nothere.mtl' not found (" + dir +
                            "/nothere.mtl); faces whose material only it would define use the "
                            "default material");
  EXPECT_WARNED_ONCE(w, path +
                            ": usemtl 'blue', 'green' name no material of the MTL files "
                            "read (a library was not read, above); faces use the default "
                            "material");
  EXPECT_EQ(w.all().size(), 2u) << w.dump();
  EXPECT_COLOUR(material_named(s, "x.obj:red").albedo, 1, 0, 0);
  ASSERT_EQ(s.triangles.size(), 3u);
  EXPECT_EQ(s.materials[s.triangles[0].material].name, "x.obj:red");
  // a symbolic link loop
  std::filesystem::create_symlink("b.mtl", dir + "/a.mtl");
  std::filesystem::create_symlink("a.mtl", dir + "/b.mtl");
  const std::string loop =
      write(dir, "loop.obj", "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n");
  CaptureWarnings w2;
  Scene l;
  load(l, loop);
  ASSERT_EQ(w2.all().size(), 1u) << w2.dump();
  EXPECT_NE(
      w2.all()[0].find(std::make_error_code(std::errc::too_many_symbolic_link_levels).message()),
      std::string::npos)
      << w2.dump();
  EXPECT_EQ(w2.all()[0].find("not found"), std::string::npos) << w2.dump();
}

// A statement OBJ does not have, in a file with vertices and faces, is ignored with one warning
// naming the first and counting the others: a typo ("f1 2 3") lost its face without a word.
// Every statement of the format (curves and surfaces included) is silent.
TEST(Obj, StatementsObjDoesNotHaveAreNamed) {
  const std::string dir = lucent::test::temp_dir();
  const std::string path = write(dir, "typo.obj",
                                 "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf1 1 3 4\n"
                                 "o name\ns off\ncstype bezier\nfo 1 3 4\n");
  CaptureWarnings w;
  Scene s;
  load(s, path);
  EXPECT_EQ(s.triangles.size(), 1u);
  EXPECT_WARNED_ONCE(w, path +
                            ":6: 'f1' is no OBJ statement; the line is ignored (and 1 more "
                            "such line)");
  EXPECT_EQ(w.all().size(), 1u) << w.dump();
}

TEST(Obj, CrlfFilesLoadLikeLfFiles) {
  std::string dir = lucent::test::temp_dir();
  const unsigned char px[] = {200, 100, 50};
  ASSERT_TRUE(stbi_write_png((dir + "/tex.png").c_str(), 1, 1, 3, px, 3));
  std::string obj =
      "# comment\nmtllib m.mtl\ng body\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
      "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
      "usemtl skin\nf 1/1/1 2/2/1 3/3/1 4/4/1\ng cloth\nusemtl red\nf 1/1/1 3/3/1 2/2/1\n";
  std::string mtl =
      "newmtl skin\nKd 1 1 1\nmap_Kd tex.png\nmap_bump \n\nnewmtl red\nKd 0.7 0.1 0.1\nillum 1\n";
  auto crlf = [](std::string s) {
    std::string out;
    for (char c : s) out += c == '\n' ? std::string("\r\n") : std::string(1, c);
    return out;
  };
  std::string lf_dir = dir + "/lf", crlf_dir = dir + "/crlf";
  write(lf_dir, "m.obj", obj);
  write(lf_dir, "m.mtl", mtl);
  write(crlf_dir, "m.obj", crlf(obj));
  write(crlf_dir, "m.mtl", crlf(mtl));
  std::filesystem::copy_file(dir + "/tex.png", lf_dir + "/tex.png");
  std::filesystem::copy_file(dir + "/tex.png", crlf_dir + "/tex.png");
  CaptureWarnings w;
  Scene a, b;
  load(a, lf_dir + "/m.obj");
  load(b, crlf_dir + "/m.obj");
  EXPECT_TRUE(w.all().empty()) << w.dump();
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.normals, b.normals);
  EXPECT_EQ(a.uvs, b.uvs);
  ASSERT_EQ(a.triangles.size(), 3u);
  ASSERT_EQ(b.triangles.size(), 3u);
  ASSERT_EQ(b.materials.size(), 2u);
  for (const Scene* s : {&a, &b}) {
    const Material& skin = material_named(*s, "m.obj:skin");
    const Material& red = material_named(*s, "m.obj:red");
    EXPECT_COLOUR(red.albedo, 0.7, 0.1, 0.1);
    ASSERT_EQ(skin.albedo_texture, 0) << "texture name read without the carriage return";
    ASSERT_EQ(s->textures.size(), 1u);
    EXPECT_EQ(s->textures[0].width, 1);
  }
}

TEST(Obj, UsemtlAppliesPerFaceAcrossGroups) {
  std::string dir = lucent::test::temp_dir();
  write(dir, "m.mtl", "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n");
  std::string path = write(dir, "faces.obj",
                           "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 2 0\n"
                           "g first\nusemtl red\nf 1 2 3\nusemtl blue\nf 1 3 4\n"
                           "g second\nf 2 5 3\nusemtl red\nf 3 5 4\nusemtl unknown\nf 1 2 5\n");
  CaptureWarnings w;
  Scene s;
  load(s, path);
  ASSERT_EQ(s.triangles.size(), 5u);
  ASSERT_EQ(w.count("'unknown'"), 1) << w.dump();
  EXPECT_EQ(w.all().size(), 1u) << w.dump();
  int red = s.find_material("faces.obj:red"), blue = s.find_material("faces.obj:blue");
  ASSERT_GE(red, 0);
  ASSERT_GE(blue, 0);
  EXPECT_EQ(s.materials[red].albedo, glm::dvec3(1, 0, 0));
  EXPECT_EQ(s.materials[blue].albedo, glm::dvec3(0, 0, 1));
  std::map<std::set<int>, int> want = {
      {{1, 2, 3}, red}, {{1, 3, 4}, blue}, {{2, 5, 3}, blue}, {{3, 5, 4}, red}};
  // vertex k of the file is scene position k - 1 (the first mesh of the scene)
  int unknown_faces = 0;
  for (const Triangle& t : s.triangles) {
    std::set<int> key = {t.v[0] + 1, t.v[1] + 1, t.v[2] + 1};
    if (want.count(key)) {
      EXPECT_EQ(t.material, want[key]) << "face " << *key.begin();
    } else {
      EXPECT_EQ(key, (std::set<int>{1, 2, 5}));
      const Material& m = s.materials[t.material];
      EXPECT_EQ(m.albedo, glm::dvec3(0.8)) << "an unknown usemtl falls back to the default";
      ++unknown_faces;
    }
  }
  EXPECT_EQ(unknown_faces, 1);
}

// A material name is the rest of its line, trimmed, for newmtl and usemtl alike (as Blender and
// assimp read both): tinyobjloader's newmtl kept the whole line but its usemtl read the first
// word, so "usemtl my mat" selected 'my' (or the default material, quoting 'my'), 3ds Max's
// names with spaces could not be used. A '#' on a newmtl line is part of the name; a usemtl
// whose whole name is not defined selects the name before its comment, as before.
TEST(Obj, MaterialNamesWithSpacesAreSelectedWhole) {
  std::string dir = lucent::test::temp_dir();
  write(dir, "m.mtl",
        "newmtl my mat\nKd 1 0 0\n"      // 'my mat'
        "newmtl my\nKd 0 1 0\n"          // 'my'
        "newmtl   padded  \nKd 0 0 1\n"  // 'padded': tinyobjloader kept the leading spaces
        "newmtl red # note\nKd 1 1 0\n"  // 'red # note'
        "newmtl plain\nKd 0 1 1\n");
  std::string path = write(dir, "names.obj",
                           "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                           "usemtl my mat\nf 1 2 3\n"  // before the mtllib (an alias and a head)
                           "mtllib m.mtl\n"
                           "usemtl my\nf 1 3 2\n"
                           "usemtl \t my mat  \nf 2 1 3 # a comment ends the face\n"
                           "usemtl padded\nf 2 3 1\n"
                           "usemtl red # note\nf 3 1 2\n"
                           "usemtl plain # the name before the comment\nf 3 2 1\n"
                           "usemtl red\nf 1 2 3\n"  // no such name
                           "usemtl my other mat\nf 1 2 3\n");
  CaptureWarnings w;
  Scene s;
  load(s, path);
  ASSERT_EQ(s.triangles.size(), 8u);
  auto name = [&](int i) { return s.materials[s.triangles[i].material].name; };
  EXPECT_EQ(name(0), "names.obj:my mat");
  EXPECT_EQ(s.materials[s.triangles[0].material].albedo, glm::dvec3(1, 0, 0));
  EXPECT_EQ(name(1), "names.obj:my");
  EXPECT_EQ(name(2), "names.obj:my mat");
  EXPECT_EQ(name(3), "names.obj:padded");
  EXPECT_EQ(s.materials[s.triangles[3].material].albedo, glm::dvec3(0, 0, 1));
  EXPECT_EQ(name(4), "names.obj:red # note");
  EXPECT_EQ(name(5), "names.obj:plain");
  EXPECT_EQ(name(6), "obj:default");
  EXPECT_EQ(name(7), "obj:default");
  EXPECT_EQ(
      w.count(path + ": usemtl 'red' names no material of the MTL file (the MTL file defines 'red "
                     "# note': a '#' on a newmtl line is part of the name, not a comment); faces "
                     "use the default material"),
      1)
      << w.dump();
  EXPECT_EQ(w.count(path + ": usemtl 'my other mat' names no material of the MTL file; faces use "
                           "the default material"),
            1)
      << w.dump();
  EXPECT_EQ(w.all().size(), 2u) << w.dump();

  // without a library, the warning quotes the whole name
  std::string none = write(dir, "none.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl my mat\nf 1 2 3\n");
  CaptureWarnings w2;
  Scene s2;
  load(s2, none);
  EXPECT_EQ(w2.count(none + ": usemtl 'my mat' but the file names no material library (mtllib); "
                            "faces use the default material"),
            1)
      << w2.dump();
  EXPECT_EQ(w2.all().size(), 1u) << w2.dump();
}

TEST(Obj, TexturesAreRelativeToTheMtlFileAndMissingOnesWarn) {
  std::string dir = lucent::test::temp_dir();
  std::filesystem::create_directories(dir + "/lib/tex");
  const unsigned char px[] = {255, 255, 255, 0, 0, 0};
  ASSERT_TRUE(stbi_write_png((dir + "/lib/tex/t.png").c_str(), 2, 1, 3, px, 6));
  write(dir, "lib/m.mtl",
        "newmtl a\nKd 0.5 0.5 0.5\nmap_Kd tex/t.png\n"
        "newmtl b\nKd 0.2 0.2 0.2\nmap_Kd tex/t.png\n"
        "newmtl c\nKd 0.3 0.4 0.5\nmap_Kd tex/nothere.png\nmap_d tex/alpha.dds\n");
  std::string path = write(dir, "mesh.obj",
                           "mtllib lib/m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\n"
                           "usemtl a\nf 1 2 3\nusemtl b\nf 1 3 2\nusemtl c\nf 2 1 3\n");
  CaptureWarnings w;
  Scene s;
  load(s, path);
  ASSERT_EQ(s.textures.size(), 1u) << "both materials share the texture";
  EXPECT_EQ(s.textures[0].width, 2);
  EXPECT_EQ(material_named(s, "mesh.obj:a").albedo_texture, 0);
  EXPECT_EQ(material_named(s, "mesh.obj:b").albedo_texture, 0);
  const Material& c = material_named(s, "mesh.obj:c");
  EXPECT_EQ(c.albedo_texture, -1);
  EXPECT_COLOUR(c.albedo, 0.3, 0.4, 0.5) << ": a missing texture falls back to Kd";
  EXPECT_EQ(w.count("nothere.png"), 1) << w.dump();
  EXPECT_EQ(w.count("alpha.dds"), 1) << w.dump();
  EXPECT_EQ(w.all().size(), 2u) << w.dump();
  for (const auto& msg : w.all()) EXPECT_NE(msg.find("m.mtl"), std::string::npos) << msg;
}

// A texture named by another machine's path (Windows' or an absolute one) that is not found is
// looked for by its file name beside the MTL file, as Blender's importer does, with a warning
// naming both; an unused map found so is not reported missing.
TEST(Obj, ATextureOfAnotherMachinesPathIsFoundBesideTheMtlFile) {
  const std::string dir = lucent::test::temp_dir();
  std::filesystem::create_directories(dir + "/lib");
  const unsigned char px[] = {255, 255, 255, 0, 0, 0};
  ASSERT_TRUE(stbi_write_png((dir + "/lib/q.png").c_str(), 2, 1, 3, px, 6));
  write(dir, "lib/m.mtl",
        "newmtl a\nKd 0.5 0.5 0.5\nmap_Kd C:\\Users\\me\\textures\\q.png\n"
        "newmtl b\nKd 0.2 0.2 0.2\nmap_Kd /nowhere/at/all/q.png\nmap_bump /nowhere/q.png\n"
        "newmtl c\nKd 0.5 0.5 0.5\nmap_Kd C:\\Users\\me\\textures\\q.png\n"
        "newmtl d\nKd 0.1 0.1 0.1\nmap_Kd /nowhere/sub\n");
  std::filesystem::create_directories(dir + "/lib/sub");  // (a directory is no texture)
  const std::string path = write(dir, "mesh.obj",
                                 "mtllib lib/m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\n"
                                 "usemtl a\nf 1 2 3\nusemtl b\nf 1 3 2\nusemtl c\nf 2 1 3\n"
                                 "usemtl d\nf 2 3 1\n");
  CaptureWarnings w;
  Scene s;
  load(s, path);
  ASSERT_EQ(s.textures.size(), 1u) << w.dump();
  EXPECT_EQ(material_named(s, "mesh.obj:a").albedo_texture, 0);
  EXPECT_EQ(material_named(s, "mesh.obj:b").albedo_texture, 0);
  EXPECT_EQ(material_named(s, "mesh.obj:c").albedo_texture, 0);
  EXPECT_EQ(material_named(s, "mesh.obj:d").albedo_texture, -1);
  // once per name (c names a's texture again); d's not found, the directory no texture
  EXPECT_EQ(w.count("its file name beside the MTL file"), 2) << w.dump();
  EXPECT_EQ(w.count("using " + dir + "/lib/q.png"), 2) << w.dump();
  EXPECT_EQ(w.count("map_Kd texture '/nowhere/sub' not found (/nowhere/sub); using Kd"), 1)
      << w.dump();
  EXPECT_EQ(w.all().size(), 3u) << w.dump();  // (not map_bump's)
}

TEST(Obj, UnreadableTextureWarnsAndFallsBack) {
  std::string dir = lucent::test::temp_dir();
  write(dir, "junk.png", "not an image");
  write(dir, "m.mtl", "newmtl a\nKd 0.1 0.2 0.3\nmap_Kd junk.png\n");
  std::string path =
      write(dir, "m.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nusemtl a\nf 1 2 3\n");
  CaptureWarnings w;
  Scene s;
  load(s, path);
  EXPECT_EQ(w.count("junk.png"), 1) << w.dump();
  EXPECT_EQ(material_named(s, "m.obj:a").albedo_texture, -1);
  EXPECT_COLOUR(material_named(s, "m.obj:a").albedo, 0.1, 0.2, 0.3);
}

// The lucent::Error of loading the OBJ file `path`; "" when it loads.
std::string load_error(const std::string& path) {
  try {
    Scene s;
    load(s, path);
  } catch (const lucent::Error& e) {
    return e.what();
  }
  return "";
}

TEST(Obj, MalformedFilesAreErrorsNamingFileAndLine) {
  std::string dir = lucent::test::temp_dir();
  const std::string head = "# a triangle\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\n";  // 5 lines
  struct Case {
    const char* name;
    std::string face;
    std::string needle;
  } cases[] = {
      {"zero.obj", "f 1 2 0\n", "index"},
      {"word.obj", "f 1 2 x\n", "index"},
      {"range.obj", "f 1 2 4\n", "out of range"},
      {"negative.obj", "f -4 1 2\n", "out of range"},
      {"texcoord.obj", "f 1/1 2/1 3/2\n", "texture coordinate"},
      {"normal.obj", "f 1//1 2//1 3//1\n", "normal"},
      {"vword.obj", "v 1 abc 0\n", "'abc' is not a number"},
      {"vshort.obj", "v 1 2\n", "vertex line has 2 numbers, needs 3"},
      {"vnword.obj", "vn 0 1 0x\n", "'0x' is not a number"},
      {"vtword.obj", "vt u 0\n", "texture coordinate line: 'u' is not"},
      {"vhuge.obj", "v 1e999 0 0\n", "out of range"},
      // tinyobjloader's skin weights: it converts joints to int unchecked (found by fuzz_obj)
      {"vwjoint.obj", "vw 1 112147483648 0.5\n",
       "skin weight line: joint '112147483648' is out of range (0 to 2147483647)"},
      {"vwnegative.obj", "vw 1 -1 0.5\n", "skin weight line: joint '-1' is out of range"},
      {"vwweight.obj", "vw 1 0 1e39\n", "skin weight line: '1e39' is out of range for a float"},
  };
  for (const Case& c : cases) {
    std::string path = write(dir, c.name, head + "f 1 2 3\n" + c.face);  // the face: line 7
    std::string err = load_error(path);
    ASSERT_FALSE(err.empty()) << c.name << " loaded";
    EXPECT_NE(err.find(path + ":7:"), std::string::npos) << c.name << ": " << err;
    EXPECT_NE(err.find(c.needle), std::string::npos) << c.name << ": " << err;
    EXPECT_EQ(err.find('\n'), std::string::npos) << "one line: " << err;
  }
  std::string missing = dir + "/nothere.obj";
  std::string err = load_error(missing);
  EXPECT_NE(err.find(missing), std::string::npos) << err;
  err = load_error(dir);
  EXPECT_NE(err.find(dir + ": "), std::string::npos) << "a directory: " << err;
}

// tinyobjloader's messages name lines as "line N" or "line: N": those numbers are shifted when
// lucent put a line before the file's text (usemtl before mtllib), and an error's first number is
// the line its message names. (std::regex did this until 1 Dec 2026; the scan gives the same
// text, checked against it on 300,000 random strings of these words.)
TEST(Obj, LineNumbersInTinyobjloadersMessagesAreShiftedAndNamed) {
  namespace obj = lucent::scene_detail::obj;
  EXPECT_EQ(
      obj::shift_line_numbers(
          "warning at line 12, then line: 3\nline:4 liner 5 line  6 line 7x, line line 10", 1),
      "warning at line 11, then line: 2\nline:4 liner 5 line  6 line 6x, line line 9");
  EXPECT_EQ(obj::shift_line_numbers("line 1", 1), "line 0");
  EXPECT_EQ(obj::shift_line_numbers("no number here", 1), "no number here");
  EXPECT_EQ(obj::shift_line_numbers("", 1), "");
  const auto error_of = [](const std::string& err) {
    try {
      obj::throw_parse_error("a.obj", err);
    } catch (const lucent::Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error_of("Failed parse `f' at line:x, line: 7 of it\nline 9"),
            "a.obj:7: malformed face: an index is 0 or not a number");
  EXPECT_EQ(error_of("something at line 12\n"), "a.obj:12: something at line 12");
  EXPECT_EQ(error_of("no number\nline 3"), "a.obj: no number");
  EXPECT_EQ(error_of(""), "a.obj: cannot parse the file");
}

// Skin weights within range load as before (lucent ignores them).
TEST(Obj, SkinWeightsInRangeLoad) {
  std::string dir = lucent::test::temp_dir();
  std::string path = write(dir, "vw.obj",
                           "v 0 0 0\nv 1 0 0\nv 1 1 0\nvw 0 0 0.25 1 0.75\nvw 1 2147483647 1\n"
                           "f 1 2 3\n");
  EXPECT_EQ(load_error(path), "");
}

TEST(Obj, TransformMovesPositionsAndNormalsByTheInverseTranspose) {
  std::string dir = lucent::test::temp_dir();
  // a sloped triangle whose vertex normals are its face normal
  glm::dvec3 a(0, 0, 0), b(1, 0, 1), c(0, 1, 0.5);
  glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "v 0 0 0\nv 1 0 1\nv 0 1 0.5\nvn %.17g %.17g %.17g\nf 1//1 2//1 3//1\n", n.x, n.y,
                n.z);
  std::string path = write(dir, "slope.obj", buf);
  glm::dmat4 xf = glm::translate(glm::dmat4(1.0), glm::dvec3(3, -2, 1)) *
                  glm::rotate(glm::dmat4(1.0), 0.7, glm::normalize(glm::dvec3(1, 2, 3))) *
                  glm::scale(glm::dmat4(1.0), glm::dvec3(2, 0.5, 3));
  Scene s;
  load(s, path, xf);
  ASSERT_EQ(s.triangles.size(), 1u);
  const Triangle& t = s.triangles[0];
  glm::dvec3 in[3] = {a, b, c};
  for (int k = 0; k < 3; ++k) {
    glm::dvec3 want = glm::dvec3(xf * glm::dvec4(in[k], 1.0));
    EXPECT_NEAR(glm::length(pos(s, t, k) - want), 0.0, 1e-6) << "vertex " << k;
  }
  // the transformed normal is unit length, perpendicular to the transformed triangle and on the
  // side of its geometric normal (non-uniform scale: the plain matrix would tilt it)
  glm::dvec3 ng = glm::normalize(geometric_normal(s, t));
  for (int k = 0; k < 3; ++k) {
    ASSERT_GE(t.n[k], 0);
    glm::dvec3 nn = s.normals[t.n[k]];
    EXPECT_NEAR(glm::length(nn), 1.0, 1e-9);
    EXPECT_NEAR(glm::dot(nn, ng), 1.0, 1e-6);
  }
  glm::dvec3 naive = glm::normalize(glm::dmat3(xf) * n);
  EXPECT_LT(glm::dot(naive, ng), 0.99) << "the test transform must tell the two apart";
}

// A flat mesh stretched by 1e300 across its plane's normal: its normals become [0, 0, 1e-300]
// before they are normalised, a direction whose squared length underflows to 0. They were
// dropped as zero (the triangle lost its normals); now they are +z.
TEST(Obj, NormalsShrunkByTheTransformKeepTheirDirection) {
  std::string dir = lucent::test::temp_dir();
  std::string path =
      write(dir, "flat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n");
  Scene s;
  load(s, path, glm::scale(glm::dmat4(1.0), glm::dvec3(1, 1, 1e300)));
  ASSERT_EQ(s.triangles.size(), 1u);
  for (int k = 0; k < 3; ++k) {
    ASSERT_GE(s.triangles[0].n[k], 0);
    EXPECT_LT(glm::length(s.normals[s.triangles[0].n[k]] - glm::dvec3(0, 0, 1)), 1e-15);
  }
}

// A unit cube around the origin, faces counter-clockwise from outside, with outward normals and
// per-face UVs equal to two of the corner's coordinates + 0.5.
const char* kCube =
    "v -0.5 -0.5 -0.5\nv 0.5 -0.5 -0.5\nv 0.5 0.5 -0.5\nv -0.5 0.5 -0.5\n"
    "v -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\nv 0.5 0.5 0.5\nv -0.5 0.5 0.5\n"
    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
    "vn 0 0 1\nvn 0 0 -1\nvn 1 0 0\nvn -1 0 0\nvn 0 1 0\nvn 0 -1 0\n"
    "f 5/1/1 6/2/1 7/3/1 8/4/1\nf 2/2/2 1/1/2 4/4/2 3/3/2\nf 6/4/3 2/1/3 3/2/3 7/3/3\n"
    "f 1/1/4 5/2/4 8/3/4 4/4/4\nf 8/1/5 7/2/5 3/3/5 4/4/5\nf 1/1/6 2/2/6 6/3/6 5/4/6\n";

void expect_outward(const Scene& s, const glm::dvec3& centre, const std::string& what) {
  ASSERT_EQ(s.triangles.size(), 12u);
  for (const Triangle& t : s.triangles) {
    glm::dvec3 ng = glm::normalize(geometric_normal(s, t));
    glm::dvec3 mid = (pos(s, t, 0) + pos(s, t, 1) + pos(s, t, 2)) / 3.0;
    EXPECT_GT(glm::dot(ng, mid - centre), 0) << what << ": a face turned inwards";
    for (int k = 0; k < 3; ++k) {
      ASSERT_GE(t.n[k], 0);
      EXPECT_NEAR(glm::dot(s.normals[t.n[k]], ng), 1.0, 1e-9)
          << what << ": normal and face disagree";
    }
  }
}

TEST(Obj, MirroringTransformKeepsOrientationAndCornerAttributes) {
  std::string dir = lucent::test::temp_dir();
  std::string path = write(dir, "cube.obj", kCube);
  Scene plain;
  load(plain, path);
  expect_outward(plain, glm::dvec3(0), "identity");

  // the course's mapping of the character: (x, z, y) * 20 + (0, -10, 0), a Y/Z swap
  glm::dmat4 swap(0.0);
  swap[0][0] = 20;  // x' = 20 x
  swap[2][1] = 20;  // y' = 20 z - 10
  swap[1][2] = 20;  // z' = 20 y
  swap[3] = glm::dvec4(0, -10, 0, 1);
  ASSERT_LT(glm::determinant(glm::dmat3(swap)), 0);
  Scene mirrored;
  load(mirrored, path, swap);
  expect_outward(mirrored, glm::dvec3(0, -10, 0), "Y/Z swap");

  // a reflection through x = 0
  Scene flipped;
  load(flipped, path, glm::scale(glm::dmat4(1.0), glm::dvec3(-1, 1, 1)));
  expect_outward(flipped, glm::dvec3(0), "x reflection");

  // every corner keeps its own position, normal and uv when two are swapped: compare each
  // mirrored corner with the untransformed one it came from
  glm::dmat4 inv = glm::inverse(swap);
  std::map<std::array<double, 5>, int> corner_set;
  for (const Triangle& t : plain.triangles)
    for (int k = 0; k < 3; ++k) {
      glm::dvec3 p = pos(plain, t, k);
      glm::dvec2 uv = plain.uvs[t.uv[k]];
      corner_set[{p.x, p.y, p.z, uv.x, uv.y}]++;
    }
  for (const Triangle& t : mirrored.triangles)
    for (int k = 0; k < 3; ++k) {
      glm::dvec3 p = glm::dvec3(inv * glm::dvec4(pos(mirrored, t, k), 1.0));
      glm::dvec3 r(std::round(p.x * 2) / 2, std::round(p.y * 2) / 2, std::round(p.z * 2) / 2);
      glm::dvec2 uv = mirrored.uvs[t.uv[k]];
      EXPECT_TRUE(corner_set.count({r.x, r.y, r.z, uv.x, uv.y}))
          << "corner (" << r.x << ", " << r.y << ", " << r.z << ") lost its uv";
    }
}

TEST(Obj, MtlMaterialsMapToLucentMaterials) {
  std::string dir = lucent::test::temp_dir();
  write(dir, "m.mtl",
        "newmtl matte\nKd 0.5 0.4 0.3\nKs 0 0 0\nNs 10\nillum 2\n"
        "newmtl shiny\nKd 0.2 0.3 0.4\nKs 0.5 0.5 0.5\nNs 98\nillum 2\n"
        "newmtl flat\nKd 0.7 0.7 0.7\nKs 0.5 0.5 0.5\nillum 1\n"
        "newmtl rough\nKd 0.5 0.5 0.5\nKs 0.04 0.04 0.04\nNs 0\nNi 1.7\nillum 2\n"
        "newmtl chrome\nKd 0 0 0\nKs 0.9 0.8 0.7\nillum 3\n"
        "newmtl glass\nKd 0 0 0\nKs 1 1 1\nNi 1.33\nillum 7\n"
        "newmtl faded\nKd 0.5 0.5 0.5\nd 0.5\nNi 1.6\nillum 2\n"
        "newmtl noni\nKd 0.5 0.5 0.5\nillum 4\n"
        "newmtl lamp\nKd 0.78 0.78 0.78\nKs 0 0 0\nKe 17 12 4\nillum 2\n");
  std::string obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\n";
  const char* names[] = {"matte", "shiny", "flat", "rough", "chrome",
                         "glass", "faded", "noni", "lamp"};
  for (const char* n : names) obj += std::string("usemtl ") + n + "\nf 1 2 3\n";
  std::string path = write(dir, "m.obj", obj);
  CaptureWarnings w;
  Scene s;
  load(s, path);
  EXPECT_TRUE(w.all().empty()) << w.dump();
  ASSERT_EQ(s.triangles.size(), 9u);
  ASSERT_EQ(s.materials.size(), 9u);
  for (size_t i = 0; i < 9; ++i)
    EXPECT_EQ(s.materials[s.triangles[i].material].name, std::string("m.obj:") + names[i]);

  const Material& matte = material_named(s, "m.obj:matte");
  EXPECT_EQ(matte.type, MaterialType::Diffuse) << "Ks 0: no specular layer";
  EXPECT_COLOUR(matte.albedo, 0.5, 0.4, 0.3);
  EXPECT_FALSE(matte.emissive());

  const Material& shiny = material_named(s, "m.obj:shiny");
  EXPECT_EQ(shiny.type, MaterialType::Plastic);
  EXPECT_COLOUR(shiny.albedo, 0.2, 0.3, 0.4);
  EXPECT_COLOUR(shiny.specular, 0.5, 0.5, 0.5);
  EXPECT_NEAR(shiny.roughness, std::sqrt(2.0 / 100.0), 1e-6);  // alpha = sqrt(2 / (Ns + 2))
  EXPECT_NEAR(shiny.ior, 1.5, 1e-12) << "no Ni: 1.5";

  EXPECT_EQ(material_named(s, "m.obj:flat").type, MaterialType::Diffuse) << "illum 1: no specular";

  const Material& rough = material_named(s, "m.obj:rough");
  EXPECT_EQ(rough.type, MaterialType::Plastic);
  EXPECT_NEAR(rough.roughness, 1.0, 1e-12);
  EXPECT_NEAR(rough.ior, 1.7, 1e-6);

  const Material& chrome = material_named(s, "m.obj:chrome");
  EXPECT_EQ(chrome.type, MaterialType::Mirror);
  EXPECT_COLOUR(chrome.specular, 0.9, 0.8, 0.7);

  const Material& glass = material_named(s, "m.obj:glass");
  EXPECT_EQ(glass.type, MaterialType::Dielectric);
  EXPECT_NEAR(glass.ior, 1.33, 1e-6);
  EXPECT_EQ(glass.specular, glm::dvec3(1.0)) << "clear glass";

  const Material& faded = material_named(s, "m.obj:faded");
  EXPECT_EQ(faded.type, MaterialType::Dielectric) << "d < 1";
  EXPECT_NEAR(faded.ior, 1.6, 1e-6);

  const Material& noni = material_named(s, "m.obj:noni");
  EXPECT_EQ(noni.type, MaterialType::Dielectric);
  EXPECT_NEAR(noni.ior, 1.5, 1e-12) << "no Ni: 1.5";

  const Material& lamp = material_named(s, "m.obj:lamp");
  EXPECT_EQ(lamp.type, MaterialType::Diffuse);
  EXPECT_EQ(lamp.emission, glm::dvec3(17, 12, 4));
  EXPECT_COLOUR(lamp.albedo, 0.78, 0.78, 0.78);
}

// A transparent material (a dielectric) takes Tf, the transmission filter, as its tint: lucent
// made every one clear, ignoring Tf without a word. A grey Tf other than 1 (Tf 0 0 0, a default
// some exporters write on every material; McGuire's Cornell boxes' Tf 0.10 on glass, meaning one
// minus the light let through) and the spectral form are said and taken as clear; a map_Kd,
// which a dielectric cannot use, is said too. Tf on an opaque material has no effect.
TEST(Obj, TransparentMaterialsTakeTfAsTint) {
  std::string dir = lucent::test::temp_dir();
  const std::string mtl =
      write(dir, "t.mtl",
            "newmtl green glass\nd 0.5\nTf 0.2 0.9 0.4\n"               // line 1
            "newmtl kt\nillum 7\nKt 0.5 0.6 0.7\n"                      // 4
            "newmtl max\nillum 2\nTr 0.3\nTf 1 1 1\n"                   // 7
            "newmtl plain\nillum 4\n"                                   // 11
            "newmtl black\nillum 6\nTf 0 0 0\n"                         // 13
            "newmtl spectral\nd 0.2\nTf spectral glass.rfl\n"           // 16
            "newmtl poly\nillum 4\nKd 0.5 0.5 0.5\nmap_Kd skin.png\n"   // 19
            "newmtl opaque\nKd 0.5 0.5 0.5\nKs 0.1 0.1 0.1\nillum 2\n"  // 23
            "Tf 0.1 0.2 0.3\n"
            "newmtl water\nKs 0.3 0.3 0.3\nTf 0.10 0.10 0.10\nillum 7\n");  // 28
  const std::vector<const char*> names = {"green glass", "kt",   "max",    "plain", "black",
                                          "spectral",    "poly", "opaque", "water"};
  const std::string path = one_face_per_material(dir, "t.obj", "t.mtl", names);
  CaptureWarnings w;
  Scene s;
  load(s, path);
  ASSERT_EQ(s.triangles.size(), 9u);
  for (const char* n : names) {
    const Material& m = material_named(s, std::string("t.obj:") + n);
    EXPECT_EQ(m.type, std::string(n) == "opaque" ? MaterialType::Plastic : MaterialType::Dielectric)
        << n;
  }
  EXPECT_COLOUR(material_named(s, "t.obj:green glass").specular, 0.2, 0.9, 0.4);
  EXPECT_COLOUR(material_named(s, "t.obj:kt").specular, 0.5, 0.6, 0.7);
  EXPECT_COLOUR(material_named(s, "t.obj:max").specular, 1, 1, 1);
  EXPECT_COLOUR(material_named(s, "t.obj:plain").specular, 1, 1, 1) << "no Tf: clear";
  EXPECT_COLOUR(material_named(s, "t.obj:black").specular, 1, 1, 1);
  EXPECT_COLOUR(material_named(s, "t.obj:spectral").specular, 1, 1, 1);
  EXPECT_COLOUR(material_named(s, "t.obj:poly").specular, 1, 1, 1);
  EXPECT_COLOUR(material_named(s, "t.obj:opaque").specular, 0.1, 0.1, 0.1) << "Ks, not Tf";
  EXPECT_COLOUR(material_named(s, "t.obj:water").specular, 1, 1, 1);
  EXPECT_WARNED_ONCE(w, mtl +
                            ":15: material 'black' (transparent: illum 6): Tf 0 0 0 is grey, which "
                            "readers take as the light let through or as one minus it; taken as "
                            "clear (tint 1): a Tf of unequal channels is the tint");
  EXPECT_WARNED_ONCE(w,
                     mtl + ":30: material 'water' (transparent: illum 7): Tf 0.1 0.1 0.1 is grey");
  EXPECT_WARNED_ONCE(w, mtl +
                            ":18: material 'spectral' (transparent: opacity 0.2 (d or Tr)): Tf "
                            "spectral (a curve) is not read; tint 1");
  EXPECT_WARNED_ONCE(w,
                     mtl +
                         ":19: material 'poly' (transparent: illum 4) becomes a dielectric, which "
                         "has no texture: its map_Kd 'skin.png' is ignored (Tf gives its tint)");
  EXPECT_EQ(w.all().size(), 4u) << w.dump();
}

// The MTL specification's other colour forms, which tinyobjloader misread without a word ("Kd xyz
// 0.3 0.4 0.5" gave Kd 0 0.3 0.4): "xyz x y z" is CIE XYZ, put in linear sRGB (D65), one number
// meaning x = y = z, a colour outside sRGB's gamut clamped with a warning; "spectral file" (a
// reflectance curve) is not read, with a warning: the colour is 0 0 0.
TEST(Obj, ColourFormsXyzAndSpectral) {
  std::string dir = lucent::test::temp_dir();
  const std::string mtl = write(dir, "c.mtl",
                                "newmtl xyz\nKd xyz 0.3 0.4 0.5\nKs xyz 0.2\nillum 2\n"  // line 1
                                "newmtl curve\nKd spectral red.rfl 1.0\n"                // 5
                                "newmtl none\nillum 1\n"                                 // 7
                                "newmtl vivid\nnewmtl\nKd xyz 0.1 0.5 0.1\n"             // 9
                                "newmtl glass\nd 0.5\nTf xyz 0.4 0.3 0.2\n"              // 12
                                "newmtl kt curve\nd 0.5\nKt spectral k.rfl\n");          // 15
  const std::string path = one_face_per_material(
      dir, "c.obj", "c.mtl", {"xyz", "curve", "none", "vivid", "glass", "kt curve"});
  CaptureWarnings w;
  Scene s;
  load(s, path);
  ASSERT_EQ(s.triangles.size(), 6u);
  // XYZ to linear sRGB (IEC 61966-2-1's matrix), computed apart: 0.3 * (3.2404542, -0.9692660,
  // 0.0556434) + 0.4 * (-1.5371385, 1.8760108, -0.2040259) + ...
  const Material& xyz = material_named(s, "c.obj:xyz");
  EXPECT_EQ(xyz.type, MaterialType::Plastic);
  EXPECT_COLOUR(xyz.albedo, 0.10801516, 0.48040252, 0.46369526);
  EXPECT_COLOUR(xyz.specular, 0.2 * 1.2047843, 0.2 * 0.9483008, 0.2 * 0.9088427);
  EXPECT_COLOUR(material_named(s, "c.obj:curve").albedo, 0, 0, 0);
  EXPECT_COLOUR(material_named(s, "c.obj:none").albedo, 0, 0, 0) << "(as without Kd)";
  // red: 0.32404542 - 0.76856925 - 0.04985314 < 0
  EXPECT_COLOUR(material_named(s, "c.obj:vivid").albedo, 0, 0.8452344, 0.00927391);
  EXPECT_EQ(material_named(s, "c.obj:glass").type, MaterialType::Dielectric);
  EXPECT_COLOUR(material_named(s, "c.obj:glass").specular, 0.73533385, 0.18340804, 0.17249463);
  EXPECT_WARNED_ONCE(w, mtl +
                            ":6: material 'curve': Kd spectral (a curve in 'red.rfl') is not "
                            "read: the material's Kd is 0 0 0");
  // (the bare "newmtl" on line 10 is no statement: the line is still vivid's)
  EXPECT_WARNED_ONCE(w, mtl +
                            ":11: material 'vivid': Kd xyz 0.1 0.5 0.1 is outside the sRGB gamut: "
                            "its negative channels are taken as 0 (Kd 0 0.8452344 0.00927391)");
  // a transparent material's Kt spectral: clear, and the warning names Kt (it said Tf)
  EXPECT_COLOUR(material_named(s, "c.obj:kt curve").specular, 1, 1, 1);
  EXPECT_WARNED_ONCE(w, mtl +
                            ":17: material 'kt curve' (transparent: opacity 0.5 (d or Tr)): Kt "
                            "spectral (a curve) is not read; tint 1");
  EXPECT_EQ(w.all().size(), 3u) << w.dump();

  // a spectral Kd beside a map_Kd that is missing: the material keeps its Kd, 0 0 0 as the
  // warning says (tinyobjloader gives 0.6 to a map_Kd without a Kd in a file where no material
  // had one: the statement was left out before)
  write(dir, "t.mtl", "newmtl tex\nKd spectral red.rfl\nmap_Kd no.png\n");
  Scene t;
  load(t, one_face_per_material(dir, "t.obj", "t.mtl", {"tex"}));
  EXPECT_COLOUR(material_named(t, "t.obj:tex").albedo, 0, 0, 0);
}

// A colour of one number is grey, as the MTL format says ("Kd 0.5": g and b are r): lucent
// refused the file, and tinyobjloader read 0.5 0 0. The number keeps its text ("1e-1").
TEST(Obj, ColourOfOneNumberIsGrey) {
  std::string dir = lucent::test::temp_dir();
  write(dir, "g.mtl",
        "newmtl grey\nKd 0.5\nKs\t1e-1 \nillum 2\n"
        "newmtl lamp\nKd 0\nKe 4\n"
        "newmtl three\nKd 0.5 0.25 0.125\n");
  CaptureWarnings w;
  Scene s;
  load(s, one_face_per_material(dir, "g.obj", "g.mtl", {"grey", "lamp", "three"}));
  EXPECT_TRUE(w.all().empty()) << w.dump();
  const Material& grey = material_named(s, "g.obj:grey");
  EXPECT_EQ(grey.type, MaterialType::Plastic);
  EXPECT_COLOUR(grey.albedo, 0.5, 0.5, 0.5);
  EXPECT_COLOUR(grey.specular, 0.1, 0.1, 0.1);
  EXPECT_COLOUR(material_named(s, "g.obj:lamp").emission, 4, 4, 4);
  EXPECT_COLOUR(material_named(s, "g.obj:three").albedo, 0.5, 0.25, 0.125);
}

// Some exporters write the illumination model as a decimal ("illum 2.0"; Blender's importer
// reads it, tinyobjloader's atoi reads 2): lucent refused the file. A decimal that is not a whole
// number (which atoi would truncate) is still refused.
TEST(Obj, IllumWrittenAsAWholeDecimalIsRead) {
  std::string dir = lucent::test::temp_dir();
  const std::string mtl = write(dir, "d.mtl",
                                "newmtl shiny\nKd 0.5 0.5 0.5\nKs 0.5 0.5 0.5\nillum 2.0\n"
                                "newmtl glass\nillum 7.000\n"
                                "newmtl matte\nKd 0.5 0.5 0.5\nKs 0.5 0.5 0.5\nillum 1.\n");
  std::string obj =
      "mtllib d.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nusemtl shiny\nf 1 2 3\n"
      "usemtl glass\nf 1 2 3\nusemtl matte\nf 1 2 3\n";
  std::string path = write(dir, "d.obj", obj);
  CaptureWarnings w;
  Scene s;
  load(s, path);
  EXPECT_TRUE(w.all().empty()) << w.dump();
  EXPECT_EQ(material_named(s, "d.obj:shiny").type, MaterialType::Plastic);
  EXPECT_EQ(material_named(s, "d.obj:glass").type, MaterialType::Dielectric);
  EXPECT_EQ(material_named(s, "d.obj:matte").type, MaterialType::Diffuse);

  for (const char* bad : {"2.5", "1e1", "2.0x", ".5"}) {
    write(dir, "d.mtl", std::string("newmtl shiny\nillum ") + bad + "\n");
    Scene s2;
    try {
      load(s2, path);
      ADD_FAILURE() << bad;
    } catch (const lucent::Error& e) {
      EXPECT_EQ(std::string(e.what()),
                mtl + ":2: illum line: '" + bad + "' is not an illumination model (0 to 10)");
    }
  }
}

TEST(Obj, MaterialOverrideIgnoresTheMtl) {
  std::string dir = lucent::test::temp_dir();
  write(dir, "m.mtl", "newmtl red\nKd 1 0 0\nmap_Kd nothere.png\n");
  std::string path = write(dir, "m.obj",
                           "mtllib m.mtl\nmtllib missing.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\n"
                           "usemtl red\nf 1 2 3\nusemtl nosuch\nf 1 3 2\n");
  CaptureWarnings w;
  Scene s;
  s.materials.push_back(Material{});
  s.materials.push_back(Material{});
  load(s, path, glm::dmat4(1.0), 1);
  EXPECT_TRUE(w.all().empty()) << w.dump();
  EXPECT_EQ(s.materials.size(), 2u);
  EXPECT_TRUE(s.textures.empty());
  ASSERT_EQ(s.triangles.size(), 2u);
  for (const Triangle& t : s.triangles) EXPECT_EQ(t.material, 1);
}

// A scene of `shapes` (JSON array items) and `materials` (JSON object items) in `dir`.
Scene load_json_scene(const std::string& dir, const std::string& materials,
                      const std::string& shapes) {
  const std::string path = write(dir, "s.json", R"({
    "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0], "fov": 45},
    "film": {"width": 4, "height": 4},
    "materials": {)" + materials + R"(},
    "shapes": [)" + shapes + R"(],
    "lights": [{"type": "environment", "radiance": [1, 1, 1]}]
  })");
  return lucent::load_scene(path);
}

// The material of each shape's triangles (all of them the same).
std::vector<int> shape_materials(const Scene& s) {
  std::vector<int> out;
  for (const lucent::ShapeEntry& e : s.shapes) {
    EXPECT_GT(e.count, 0u) << e.file;
    for (std::size_t i = e.first; i < e.first + e.count; ++i)
      EXPECT_EQ(s.triangles[i].material, s.triangles[e.first].material) << e.file;
    out.push_back(e.count > 0 ? s.triangles[e.first].material : -1);
  }
  return out;
}

// Two OBJ files with the same file name, a/model.obj and b/model.obj, each with its model.mtl
// defining 'paint' (red, blue): the second mesh took the first one's material ("model.obj:paint",
// found by name, was taken for "the same OBJ loaded again"): both red, "materials 1", no warning.
// A material is shared only when it is the same MTL material (library and name); the same OBJ
// loaded again, or another OBJ naming the same library, shares it. The second name gets the
// parent directory in front.
TEST(Obj, SameNamedObjFilesKeepTheirOwnMaterials) {
  std::string dir = lucent::test::temp_dir();
  const std::string triangle = "v -1 -1 0\nv 1 -1 0\nv 0 1 0\n";
  write(dir, "a/model.mtl", "newmtl paint\nKd 1 0 0\n");
  write(dir, "a/model.obj", "mtllib model.mtl\n" + triangle + "usemtl paint\nf 1 2 3\n");
  write(dir, "b/model.mtl", "newmtl paint\nKd 0 0 1\n");
  write(dir, "b/model.obj", "mtllib model.mtl\n" + triangle + "usemtl paint\nf 1 2 3\n");
  write(dir, "a/other.obj", "mtllib model.mtl\n" + triangle + "usemtl paint\nf 1 2 3\n");
  CaptureWarnings w;
  const Scene s = load_json_scene(dir, "",
                                  R"({"type": "mesh", "file": "a/model.obj"},
                                     {"type": "mesh", "file": "b/model.obj"},
                                     {"type": "mesh", "file": "a/model.obj"},
                                     {"type": "mesh", "file": "a/other.obj"})");
  EXPECT_TRUE(w.all().empty()) << w.dump();
  ASSERT_EQ(s.materials.size(), 2u);
  const std::vector<int> m = shape_materials(s);
  ASSERT_EQ(m.size(), 4u);
  EXPECT_EQ(s.materials[m[0]].name, "model.obj:paint");
  EXPECT_EQ(s.materials[m[0]].albedo, glm::dvec3(1, 0, 0));
  EXPECT_EQ(s.materials[m[1]].name, "b/model.obj:paint");
  EXPECT_EQ(s.materials[m[1]].albedo, glm::dvec3(0, 0, 1));
  EXPECT_EQ(m[2], m[0]) << "the same OBJ loaded again shares its materials";
  EXPECT_EQ(m[3], m[0]) << "an OBJ naming the same library shares its materials";
}

// A material of the scene's own named like an MTL material ("model.obj:paint") replaced it, and
// one named "obj:default" became the OBJ default material, silently. The OBJ's faces keep their
// own materials, under names made free.
TEST(Obj, SceneMaterialsNamedLikeObjMaterialsAreNotUsedForTheObj) {
  std::string dir = lucent::test::temp_dir();
  write(dir, "a/model.mtl", "newmtl paint\nKd 1 0 0\n");
  write(dir, "a/model.obj",
        "mtllib model.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nusemtl paint\nf 1 2 3\n"
        "usemtl nosuch\nf 1 3 2\n");
  CaptureWarnings w;  // nosuch
  const Scene s = load_json_scene(dir,
                                  R"("model.obj:paint": {"type": "diffuse", "albedo": [0, 1, 0]},
         "obj:default": {"type": "diffuse", "albedo": [0, 0.5, 0]})",
                                  R"({"type": "mesh", "file": "a/model.obj"},
         {"type": "sphere", "center": [0, 0, -5], "radius": 1, "material": "model.obj:paint"})");
  EXPECT_EQ(w.count("'nosuch'"), 1) << w.dump();
  ASSERT_EQ(s.materials.size(), 4u);
  ASSERT_EQ(s.triangles.size(), 2u);
  const Material& paint = s.materials[s.triangles[0].material];
  const Material& fallback = s.materials[s.triangles[1].material];
  EXPECT_EQ(paint.name, "a/model.obj:paint");
  EXPECT_EQ(paint.albedo, glm::dvec3(1, 0, 0));
  EXPECT_EQ(fallback.name, "obj:default#2");
  EXPECT_EQ(fallback.albedo, glm::dvec3(0.8));
  EXPECT_EQ(s.spheres.at(0).material, s.find_material("model.obj:paint"));
  EXPECT_EQ(material_named(s, "model.obj:paint").albedo, glm::dvec3(0, 1, 0));
  EXPECT_EQ(material_named(s, "obj:default").albedo, glm::dvec3(0, 0.5, 0));
}

// The MTL specification makes v and w optional in `-o u [v [w]]`, `-s` and `-t`; tinyobjloader
// takes three numbers, the file name among them: `map_Kd -o 0.5 tex.png` had no texture, and no
// warning. Each option takes the arguments that fit it; the file name is never one of them.
TEST(Obj, TextureOptionsKeepTheFileName) {
  std::string dir = lucent::test::temp_dir();
  const unsigned char px[] = {255, 255, 255, 0, 0, 0};
  ASSERT_TRUE(stbi_write_png((dir + "/t.png").c_str(), 2, 1, 3, px, 6));
  ASSERT_TRUE(stbi_write_png((dir + "/my t.png").c_str(), 2, 1, 3, px, 6));
  const char* maps[] = {"-o 0.5 t.png",
                        "-s 2 t.png",
                        "-t 0.1 0.2 t.png",
                        "-o 0.5 0.5 0 t.png",
                        "-s 2 -o 1 t.png",
                        "-clamp on -bm 1 -mm 0 1 t.png",
                        "-blendu off\t-blendv on -boost 2 -texres 512 t.png",
                        "-imfchan r -type sphere -colorspace sRGB t.png",
                        "-cc on t.png",
                        "-clamp t.png",
                        "-s 2 my t.png",
                        "t.png",
                        "my t.png"};
  std::string mtl, obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\n";
  for (std::size_t i = 0; i < std::size(maps); ++i) {
    mtl += "newmtl m" + std::to_string(i) + "\nKd 0.1 0.2 0.3\nmap_Kd " + maps[i] + "\n";
    obj += "usemtl m" + std::to_string(i) + "\nf 1 2 3\n";
  }
  // a missing texture of an unused map is still named, options or not
  mtl += "newmtl d\nKd 0.1 0.2 0.3\nmap_d -o 0.5 nothere.dds\n";
  obj += "usemtl d\nf 1 2 3\n";
  write(dir, "m.mtl", mtl);
  std::string path = write(dir, "m.obj", obj);
  CaptureWarnings w;
  Scene s;
  load(s, path);
  ASSERT_EQ(s.triangles.size(), std::size(maps) + 1);
  ASSERT_EQ(s.textures.size(), 2u) << w.dump();
  for (std::size_t i = 0; i < std::size(maps); ++i) {
    const Material& m = s.materials[s.triangles[i].material];
    EXPECT_EQ(m.albedo_texture, std::string(maps[i]).find("my t") == std::string::npos ? 0 : 1)
        << "map_Kd " << maps[i];
    EXPECT_EQ(m.albedo, glm::dvec3(1.0)) << "map_Kd " << maps[i];
  }
  EXPECT_EQ(w.count("'nothere.dds' not found"), 1) << w.dump();
  // and the options that would change the look are named once (TextureOptionsThatChangeTheLook)
  // but for -s, -o and -clamp, which are read (MapKdScaleOffsetAndClampAreRead)
  EXPECT_EQ(w.count("m.mtl: map_Kd options that lucent does not support are ignored: "
                    "'-t 0.1 0.2' (line 9), '-cc on' (line 27) (of map_Kd's options lucent reads "
                    "-s, -o and -clamp"),
            1)
      << w.dump();
  EXPECT_EQ(w.all().size(), 2u) << w.dump();
}

// lucent reads a map_Kd image as decoded, honouring -s, -o and -clamp only: a model whose MTL
// asks for turbulence, a colour remapping (-mm) or another colour space rendered otherwise than
// it asked, without a word. One warning per MTL file names such options; those at their
// defaults, those lucent reads, and those without an effect on a colour map here, are not
// named (-s, -o and -clamp were, until lucent read them).
TEST(Obj, TextureOptionsThatChangeTheLookAreNamed) {
  std::string dir = lucent::test::temp_dir();
  const unsigned char px[] = {255, 255, 255, 0, 0, 0};
  ASSERT_TRUE(stbi_write_png((dir + "/t.png").c_str(), 2, 1, 3, px, 6));
  write(dir, "quiet.mtl",
        "newmtl a\nmap_Kd -s 1 1 1 -o 0 0 -t 0 -mm 0 1 -clamp off -cc off -colorspace sRGB "
        "-blendu off -boost 2 -texres 64 -imfchan r t.png\n"
        "newmtl b\nmap_Ks -s 4 4 t.png\nmap_bump -bm 2 -clamp on t.png\n"
        "newmtl c\nmap_Kd -s 4 4 -o 0.5 0.25 -clamp on t.png\n");
  write(dir, "loud.mtl",
        "newmtl a\nKd 1 1 1\n\nmap_Kd -mm 0.2 1 -colorspace linear t.png\n"
        "newmtl b\nmap_Kd -mm 0 2 -s 1 3 t.png\n");
  for (const char* lib : {"quiet", "loud"}) {
    std::string path = write(dir, std::string(lib) + ".obj",
                             std::string("mtllib ") + lib +
                                 ".mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nusemtl a\nf 1 2 3\n"
                                 "usemtl b\nf 1 3 2\n");
    CaptureWarnings w;
    Scene s;
    load(s, path);
    if (std::string(lib) == "quiet") {
      EXPECT_EQ(w.all().size(), 0u) << w.dump();
    } else {
      EXPECT_EQ(w.count("loud.mtl: map_Kd options that lucent does not support are ignored: "
                        "'-mm 0.2 1' (line 4), '-colorspace linear' (line 4), '-mm 0 2' (line 6) "
                        "(of map_Kd's options"),
                1)
          << w.dump();
      EXPECT_EQ(w.all().size(), 1u) << w.dump();
    }
  }
}

// map_Kd's -s u [v [w]] and -o u [v [w]] are the texture's uv scale and offset (the lookup reads
// uv * scale + offset; v defaults to 1 and 0, w is ignored) and -clamp on clamps it to edge in u
// and v (`-clamp` alone is on); the last map_Kd of a material is the one read, options included.
// lucent stripped them with a warning (the image was mapped once per uv unit, repeating). A
// texture that is not found leaves Kd, and no mapping.
TEST(Obj, MapKdScaleOffsetAndClampAreRead) {
  std::string dir = lucent::test::temp_dir();
  const unsigned char px[] = {255, 255, 255, 0, 0, 0};
  ASSERT_TRUE(stbi_write_png((dir + "/t.png").c_str(), 2, 1, 3, px, 6));
  const char* maps[] = {"-s 2 3 1 -o 0.25 0.5 0 -clamp on t.png",
                        "-s 2 t.png",
                        "-o -0.5 t.png",
                        "-clamp t.png",
                        "-clamp off -s 4 4 t.png\nmap_Kd t.png",
                        "-clamp on -t 0.1 t.png",
                        "-s 2 2 missing.png"};
  std::string mtl, obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\n";
  for (std::size_t i = 0; i < std::size(maps); ++i) {
    mtl += "newmtl m" + std::to_string(i) + "\nKd 0.1 0.2 0.3\nmap_Kd " + maps[i] + "\n";
    obj += "usemtl m" + std::to_string(i) + "\nf 1 2 3\n";
  }
  write(dir, "m.mtl", mtl);
  const std::string path = write(dir, "m.obj", obj);
  CaptureWarnings w;
  Scene s;
  load(s, path);
  ASSERT_EQ(s.triangles.size(), std::size(maps));
  struct Want {
    glm::dvec2 scale, offset;
    lucent::TextureWrap wrap;
    int texture;
  };
  using W = lucent::TextureWrap;
  const Want want[] = {{{2, 3}, {0.25, 0.5}, W::Clamp, 0}, {{2, 1}, {0, 0}, W::Repeat, 0},
                       {{1, 1}, {-0.5, 0}, W::Repeat, 0},  {{1, 1}, {0, 0}, W::Clamp, 0},
                       {{1, 1}, {0, 0}, W::Repeat, 0},     {{1, 1}, {0, 0}, W::Clamp, 0},
                       {{1, 1}, {0, 0}, W::Repeat, -1}};
  for (std::size_t i = 0; i < std::size(maps); ++i) {
    const Material& m = s.materials[s.triangles[i].material];
    SCOPED_TRACE(std::string("map_Kd ") + maps[i]);
    EXPECT_EQ(m.albedo_texture, want[i].texture);
    EXPECT_EQ(m.albedo_uv_scale, want[i].scale);
    EXPECT_EQ(m.albedo_uv_offset, want[i].offset);
    EXPECT_EQ(m.albedo_wrap_u, want[i].wrap);
    EXPECT_EQ(m.albedo_wrap_v, want[i].wrap);
  }
  // only -t is named, and the missing texture
  EXPECT_EQ(w.count("m.mtl: map_Kd options that lucent does not support are ignored: "
                    "'-t 0.1' (line 19) (of map_Kd's options lucent reads -s, -o and -clamp; the "
                    "image is otherwise used as decoded)"),
            1)
      << w.dump();
  EXPECT_EQ(w.count("'missing.png' not found"), 1) << w.dump();
  EXPECT_EQ(w.all().size(), 2u) << w.dump();
}

// A scale or offset the scene format refuses is an error at the map_Kd's line, named by its
// option (docs/obj-mtl.md).
TEST(Obj, MapKdScaleAndOffsetOutOfRangeAreErrors) {
  std::string dir = lucent::test::temp_dir();
  const unsigned char px[] = {255, 255, 255, 0, 0, 0};
  ASSERT_TRUE(stbi_write_png((dir + "/t.png").c_str(), 2, 1, 3, px, 6));
  const std::string obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nusemtl a\nf 1 2 3\n";
  const std::pair<const char*, const char*> cases[] = {
      {"-s 0 1",
       "m.mtl:3: material 'a': albedo/uv_scale/0 (map_Kd -s): must be between 1e-06 "
       "and 1e+06 in magnitude (either sign), got 0"},
      {"-s 1 1e999", "m.mtl:3: material 'a': albedo/uv_scale/1 (map_Kd -s): must be a finite "},
      {"-o 0 -2e6",
       "m.mtl:3: material 'a': albedo/uv_offset/1 (map_Kd -o): must be at most "
       "1e+06 in magnitude, got -2e+06"}};
  for (const auto& [options, message] : cases) {
    write(dir, "m.mtl", std::string("newmtl a\nKd 1 1 1\nmap_Kd ") + options + " t.png\n");
    const std::string path = write(dir, "m.obj", obj);
    Scene s;
    try {
      load(s, path);
      ADD_FAILURE() << "no error for map_Kd " << options;
    } catch (const lucent::Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(message), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

// mtllib names as exporters write them: a tab separates two names and ends the line ('a.mtl\t'
// was not found), "\ " escapes a space, a backslash before anything else is a Windows
// separator ("sub\s.mtl" looked for "subs.mtl"), and an unescaped name with spaces is read whole
// when it is a library and a name split from it is not ("my lib.mtl" looked for "my" and
// "lib.mtl"). Each case gave its faces the default material, with a warning.
TEST(Obj, MtllibNamesAsExportersWriteThem) {
  std::string dir = lucent::test::temp_dir();
  write(dir, "a.mtl", "newmtl a\nKd 1 0 0\n");
  write(dir, "b.mtl", "newmtl b\nKd 0 1 0\n");
  write(dir, "sub/s.mtl", "newmtl s\nKd 0 0 1\n");
  write(dir, "my lib.mtl", "newmtl m\nKd 1 1 0\n");
  write(dir, "c d.mtl", "newmtl c\nKd 0 1 1\n");
  struct Case {
    const char* line;
    std::vector<const char*> materials;
  } cases[] = {
      {"mtllib a.mtl\t", {"a"}},
      {"mtllib\ta.mtl\tb.mtl", {"a", "b"}},
      {"mtllib sub\\s.mtl", {"s"}},
      {"mtllib my lib.mtl", {"m"}},
      {"mtllib c\\ d.mtl a.mtl", {"c", "a"}},
      {"mtllib a.mtl b.mtl # both", {"a", "b"}},
  };
  for (const Case& c : cases) {
    std::string obj = std::string(c.line) + "\nv 0 0 0\nv 1 0 0\nv 1 1 0\n";
    for (const char* m : c.materials) obj += std::string("usemtl ") + m + "\nf 1 2 3\n";
    const std::string path = write(dir, "m.obj", obj);
    CaptureWarnings w;
    Scene s;
    load(s, path);
    EXPECT_TRUE(w.all().empty()) << c.line << "\n" << w.dump();
    ASSERT_EQ(s.triangles.size(), c.materials.size()) << c.line;
    for (size_t k = 0; k < c.materials.size(); ++k)
      EXPECT_EQ(s.materials[s.triangles[k].material].name, std::string("m.obj:") + c.materials[k])
          << c.line;
  }
  // a name split from a line that is no library either: the names as split, each warned of
  CaptureWarnings w;
  Scene s;
  load(s, write(dir, "x.obj", "mtllib no such.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n"));
  EXPECT_EQ(w.count("material library 'no' not found"), 1) << w.dump();
  EXPECT_EQ(w.count("material library 'such.mtl' not found"), 1) << w.dump();
}

// A usemtl before the file's mtllib: tinyobjloader looks the name up when it reads the usemtl,
// and had read no library yet: the faces got the default material and the warning said the MTL
// file has no such material. The libraries of every mtllib are read first; tinyobjloader's line
// numbers stay those of the file. An mtllib naming two libraries read only the first one.
TEST(Obj, UsemtlBeforeMtllibUsesTheLibrary) {
  std::string dir = lucent::test::temp_dir();
  write(dir, "a.mtl", "newmtl red\nKd 1 0 0\n");
  write(dir, "b.mtl", "newmtl blue\nKd 0 0 1\n");
  write(dir, "c.mtl", "newmtl green\nKd 0 1 0\n");
  std::string path = write(dir, "late.obj",
                           "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                           "usemtl red\nf 1 2 3\n"    // lines 4, 5
                           "g \n"                     // line 6: tinyobjloader warns
                           "usemtl green\nf 1 3 2\n"  // lines 7, 8
                           "mtllib a.mtl\n"           // line 9
                           "usemtl blue\nf 2 1 3\n"   // lines 10, 11
                           "mtllib b.mtl c.mtl\n"     // line 12
                           "usemtl green\nf 3 2 1\n");
  CaptureWarnings w;
  Scene s;
  load(s, path);
  ASSERT_EQ(s.triangles.size(), 4u);
  EXPECT_EQ(s.materials[s.triangles[0].material].name, "late.obj:red");
  EXPECT_EQ(s.materials[s.triangles[0].material].albedo, glm::dvec3(1, 0, 0));
  EXPECT_EQ(s.materials[s.triangles[1].material].name, "late.obj:green");
  EXPECT_EQ(s.materials[s.triangles[1].material].albedo, glm::dvec3(0, 1, 0));
  EXPECT_EQ(s.materials[s.triangles[2].material].name, "late.obj:blue");
  EXPECT_EQ(s.materials[s.triangles[2].material].albedo, glm::dvec3(0, 0, 1));
  EXPECT_EQ(s.materials[s.triangles[3].material].name, "late.obj:green") << "c.mtl is read";
  EXPECT_EQ(w.count("Empty group name. line: 6"), 1) << w.dump();
  EXPECT_EQ(w.all().size(), 1u) << w.dump();

  // no mtllib at all: the warning says so
  std::string none = write(dir, "none.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n");
  CaptureWarnings w2;
  Scene s2;
  load(s2, none);
  EXPECT_EQ(w2.count(none + ": usemtl 'red' but the file names no material library (mtllib); "
                            "faces use the default material"),
            1)
      << w2.dump();
  EXPECT_EQ(w2.all().size(), 1u) << w2.dump();
}

// A material defined twice: tinyobjloader keeps the first definition, silently (a JSON scene
// refuses a material name given twice). A warning names both places, in one library or two.
TEST(Obj, MaterialDefinedTwiceWarnsNamingBothPlaces) {
  std::string dir = lucent::test::temp_dir();
  write(dir, "twice.mtl", "newmtl m\nKd 1 0 0\n\nnewmtl m\nKd 0 1 0\nnewmtl n  \nKd 0 0 1\n");
  write(dir, "more.mtl", "# n again\nnewmtl n\nKd 1 1 0\n");
  std::string path = write(dir, "m.obj",
                           "mtllib twice.mtl\nmtllib more.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                           "usemtl m\nf 1 2 3\nusemtl n\nf 1 3 2\n");
  CaptureWarnings w;
  Scene s;
  load(s, path);
  ASSERT_EQ(s.triangles.size(), 2u);
  EXPECT_EQ(s.materials[s.triangles[0].material].albedo, glm::dvec3(1, 0, 0));
  EXPECT_EQ(s.materials[s.triangles[1].material].albedo, glm::dvec3(0, 0, 1));
  EXPECT_EQ(w.count(dir + "/twice.mtl:4: material 'm' is defined again (first at line 1); "
                          "faces use the first definition"),
            1)
      << w.dump();
  EXPECT_EQ(w.count(dir + "/more.mtl:2: material 'n' is defined again (first at " + dir +
                    "/twice.mtl:6); faces use the first definition"),
            1)
      << w.dump();
  EXPECT_EQ(w.all().size(), 2u) << w.dump();
}

// The MTL libraries an OBJ file names are inputs of the scene, as its textures are: outputs
// (render -o, converge --csv, --plot and --save-reference, lucent-mpi -o) must not overwrite them.
// scene_inputs listed the OBJ files but not their libraries (`converge --csv lib/m.mtl` replaced
// a material library with CSV text). A library that does not exist is no input, nor is one of a
// mesh whose material override reads no MTL; a texture of an MTL material is one of the scene's.
TEST(Obj, MtlLibrariesAreInputsOfTheScene) {
  std::string dir = lucent::test::temp_dir();
  std::filesystem::create_directories(dir + "/lib/tex");
  const unsigned char px[] = {255, 255, 255, 0, 0, 0};
  ASSERT_TRUE(stbi_write_png((dir + "/lib/tex/t.png").c_str(), 2, 1, 3, px, 6));
  write(dir, "lib/m.mtl", "newmtl a\nKd 0.5 0.5 0.5\nmap_Kd tex/t.png\n");
  write(dir, "over.mtl", "newmtl b\nKd 0.5 0.5 0.5\n");
  const std::string triangle = "v 0 0 -1\nv 1 0 -1\nv 1 1 -1\n";
  write(dir, "mesh.obj",
        "mtllib lib/m.mtl\nmtllib missing.mtl\n" + triangle + "usemtl a\nf 1 2 3\n");
  write(dir, "over.obj", "mtllib over.mtl\n" + triangle + "usemtl b\nf 1 2 3\n");
  const std::string scene_path = write(dir, "s.json", R"({
    "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0], "fov": 45},
    "film": {"width": 4, "height": 4},
    "materials": {"m": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
    "shapes": [{"type": "mesh", "file": "mesh.obj"},
               {"type": "mesh", "file": "over.obj", "material": "m"}],
    "lights": [{"type": "environment", "radiance": [1, 1, 1]}]
  })");
  CaptureWarnings w;  // missing.mtl
  const Scene scene = lucent::load_scene(scene_path);
  ASSERT_EQ(scene.shapes.size(), 2u);
  EXPECT_EQ(scene.shapes[0].libraries, std::vector<std::string>{dir + "/lib/m.mtl"});
  EXPECT_TRUE(scene.shapes[1].libraries.empty());
  EXPECT_EQ(lucent::scene_detail::scene_inputs(scene_path, scene),
            (std::vector<std::string>{scene_path, dir + "/lib/tex/t.png", dir + "/mesh.obj",
                                      dir + "/lib/m.mtl", dir + "/over.obj"}));
  EXPECT_EQ(w.count("missing.mtl"), 1) << w.dump();
}

TEST(Obj, MeshesAppendToTheScene) {
  std::string dir = lucent::test::temp_dir();
  std::string path =
      write(dir, "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1 3/1/1\n");
  Scene s;
  s.positions = {glm::dvec3(9), glm::dvec3(8)};
  s.normals = {glm::dvec3(0, 1, 0)};
  s.uvs = {glm::dvec2(0.5), glm::dvec2(0.25), glm::dvec2(0.75)};
  load(s, path, glm::translate(glm::dmat4(1.0), glm::dvec3(0, 0, 5)));
  ASSERT_EQ(s.triangles.size(), 1u);
  const Triangle& t = s.triangles[0];
  EXPECT_EQ(t.v[0], 2);
  EXPECT_EQ(t.n[0], 1);
  EXPECT_EQ(t.uv[0], 3);
  EXPECT_EQ(s.positions[t.v[1]], glm::dvec3(1, 0, 5));
}

}  // namespace

}  // namespace test_obj

// (the next file of its unity batch may define its own)
#undef EXPECT_COLOUR
#undef EXPECT_WARNED_ONCE
