// The registries (kernels/shared/registry.h) reach every table: each entry of every type list is
// walked through the scene file (name -> enum), the command line (--integrator, via `lucent info`),
// `lucent info`'s report and `lucent converge`'s settings, back to its name, and the kernel
// feature define of each type a scene uses is in the scene's build options. A type added to a
// registry and forgotten in one of these places fails here. Where a type needs parameters in a
// scene file, the tables below hold a scene for it; a registry entry without one fails too.
#include <gtest/gtest.h>

#include <cstdlib>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include "lucent/converge.hpp"
#include "lucent/lucent.hpp"
#include "support.hpp"

namespace test_registry {

namespace {

using lucent::TypeEntry;
using lucent::TypeList;

std::string q(const std::string& s) { return "'" + s + "'"; }

/// `lucent info` of a scene file holding `json` (with extra arguments), parsed.
std::map<std::string, std::string> info(const std::string& json, const std::string& args = "") {
  std::string path = lucent::test::temp_dir() + "/scene.json";
  lucent::test::write_file(path, json);
  lucent::test::CommandResult r = lucent::test::run_cli("info " + q(path) + " " + args);
  EXPECT_EQ(r.status, 0) << json << "\n" << r.err;
  return lucent::test::parse_report(r.out);
}

/// The "-D LC_HAS_..." defines of a build options line.
std::set<std::string> defines(const std::string& options) {
  std::set<std::string> out;
  std::istringstream in(options);
  for (std::string word; in >> word;)
    if (word == "-D" && in >> word) out.insert(word);
  return out;
}

/// Every kernel feature define (`info --no-specialize` compiles them all).
const std::set<std::string>& kernel_features() {
  static const std::set<std::string> all =
      defines(info("{}", "--no-specialize")["kernel/build options"]);
  return all;
}

/// `feature` is among the scene's defines, when it is a kernel feature at all.
void expect_feature(const std::map<std::string, std::string>& report, const std::string& feature,
                    const std::string& what) {
  if (!kernel_features().count(feature)) return;
  EXPECT_TRUE(defines(report.at("kernel/build options")).count(feature))
      << what << ": " << feature << " missing from " << report.at("kernel/build options");
}

const char* kSphere = R"({"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "%s"})";
const char* kTriangles =
    R"({"type": "triangles", "positions": [[0,0,0],[1,0,0],[0,1,0]], "indices": [0,1,2], "material": "%s"})";

std::string with_material(const char* shape, const std::string& material) {
  std::string s = shape;
  s.replace(s.find("%s"), 2, material);
  return s;
}

// Integrators and AOVs: the scene file, --integrator (through `lucent info`, which shares the
// parser with `render`), converge's integrator=, the info report and the kernel define.
TEST(Registry, Integrators) {
  ASSERT_GE(kernel_features().size(), 10u) << "no feature defines in `info --no-specialize`";
  int n = 0;
  for (const TypeEntry<lucent::IntegratorType>& e : TypeList<lucent::IntegratorType>::entries) {
    ++n;
    const std::string name = e.name;
    lucent::Scene s = lucent::parse_scene(R"({"integrator": {"type": ")" + name + "\"}}", "i.json");
    EXPECT_EQ(s.integrator.type, e.value) << name;
    EXPECT_STREQ(lucent::type_name(e.value), e.name);

    lucent::ConvergeSetting c = lucent::parse_converge_setting("integrator=" + name);
    lucent::Scene applied;
    lucent::RenderOptions options;
    c.apply(applied, options);
    EXPECT_EQ(applied.integrator.type, e.value) << name;

    std::map<std::string, std::string> m =
        info(R"({"materials": {"m": {"type": "diffuse"}}, "shapes": [)" +
                 with_material(kSphere, "m") + "]}",
             "--integrator " + name);
    EXPECT_EQ(m["integrator"].substr(0, name.size() + 1), name + ",") << m["integrator"];
    expect_feature(m, e.feature, name);
  }
  EXPECT_EQ(n, int(lucent::IntegratorType::Primitive) + 1);  // every value has an entry

  // --aov takes every AOV (and the variance), as its help says
  lucent::test::CommandResult help = lucent::test::run_cli("render --help");
  for (const TypeEntry<lucent::IntegratorType>& e : TypeList<lucent::IntegratorType>::entries)
    if (lucent::is_aov(e.value)) {
      EXPECT_NE(help.out.find(std::string(e.name) + ","), std::string::npos) << e.name;
    }
}

// Pixel filters: the scene file (with the registry's default radius), converge's filter=, the
// info report and the kernel define.
TEST(Registry, Filters) {
  for (const TypeEntry<lucent::FilterType>& e : TypeList<lucent::FilterType>::entries) {
    const std::string name = e.name;
    const std::string json = R"({"film": {"filter": {"type": ")" + name + "\"}}}";
    lucent::Scene s = lucent::parse_scene(json, "f.json");
    EXPECT_EQ(s.film.filter.type, e.value) << name;
    EXPECT_EQ(s.film.filter.radius, lucent::default_filter_radius(e.value)) << name;

    lucent::Scene applied;
    applied.film.filter = {
        e.value == lucent::FilterType::Box ? lucent::FilterType::Tent : lucent::FilterType::Box,
        3.0};
    lucent::RenderOptions options;
    lucent::parse_converge_setting("filter=" + name).apply(applied, options);
    EXPECT_EQ(applied.film.filter.type, e.value) << name;
    EXPECT_EQ(applied.film.filter.radius, lucent::default_filter_radius(e.value)) << name;

    std::map<std::string, std::string> m = info(json);
    std::ostringstream radius;
    radius << lucent::default_filter_radius(e.value);
    EXPECT_EQ(m["filter"], name + ", radius " + radius.str());
    expect_feature(m, e.feature, name);
  }
}

// Material types: a scene using each type loads with it, and info counts each by its name.
TEST(Registry, Materials) {
  std::string materials, shapes;
  for (const TypeEntry<lucent::MaterialType>& e : TypeList<lucent::MaterialType>::entries) {
    std::string name = e.name;
    materials +=
        (materials.empty() ? "" : ", ") + ("\"" + name + "\": {\"type\": \"" + name + "\"}");
    shapes += (shapes.empty() ? "" : ", ") + with_material(kSphere, name);
  }
  const std::string json = "{\"materials\": {" + materials + "}, \"shapes\": [" + shapes + "]}";
  lucent::Scene s = lucent::parse_scene(json, "m.json");
  std::map<std::string, std::string> m = info(json);
  for (const TypeEntry<lucent::MaterialType>& e : TypeList<lucent::MaterialType>::entries) {
    int i = s.find_material(e.name);
    ASSERT_GE(i, 0) << e.name;
    EXPECT_EQ(s.materials[i].type, e.value) << e.name;
    EXPECT_STREQ(lucent::type_name(e.value), e.name);
    EXPECT_EQ(m[std::string("materials/") + e.name], "1") << e.name;
    expect_feature(m, e.feature, e.name);
  }
}

// Light types: point lights and environments from "lights", sphere and triangle lights from
// emissive shapes; info counts each by its name (and no other type).
TEST(Registry, Lights) {
  std::string dir = lucent::test::temp_dir();
  lucent::write_image(dir + "/sky.pfm", lucent::Image{2, 1, std::vector<float>(6, 0.5f)});
  const std::string emissive =
      R"("materials": {"lamp": {"type": "diffuse", "emission": [1, 1, 1]}})";
  // a scene with exactly one light of each type
  const std::map<std::string, std::string> scenes = {
      {"point",
       R"({"lights": [{"type": "point", "position": [0, 1, 0], "intensity": [1, 1, 1]}]})"},
      {"environment", R"({"lights": [{"type": "environment", "radiance": [1, 1, 1]}]})"},
      {"environment_map",
       R"({"lights": [{"type": "environment_map", "file": ")" + dir + R"(/sky.pfm"}]})"},
      {"sphere", "{" + emissive + ", \"shapes\": [" + with_material(kSphere, "lamp") + "]}"},
      {"triangle", "{" + emissive + ", \"shapes\": [" + with_material(kTriangles, "lamp") + "]}"},
  };
  for (const TypeEntry<lucent::LightType>& e : TypeList<lucent::LightType>::entries) {
    auto it = scenes.find(e.name);
    ASSERT_NE(it, scenes.end()) << "no test scene for the light type '" << e.name << "'";
    lucent::Scene s = lucent::parse_scene(it->second, "l.json");
    if (lucent::is_shape_light(e.value)) {
      EXPECT_TRUE(s.lights.empty()) << e.name;
      // and "lights" refuses it by name
      std::string message;
      try {
        lucent::parse_scene(R"({"lights": [{"type": ")" + std::string(e.name) + "\"}]}", "l.json");
      } catch (const lucent::Error& err) {
        message = err.what();
      }
      EXPECT_NE(message.find("emissive shapes"), std::string::npos) << message;
    } else {
      ASSERT_EQ(s.lights.size(), 1u) << e.name;
      EXPECT_EQ(s.lights[0].type, e.value) << e.name;
    }
    std::map<std::string, std::string> m = info(it->second);
    EXPECT_EQ(m["lights"], "1") << e.name;
    for (const TypeEntry<lucent::LightType>& other : TypeList<lucent::LightType>::entries)
      EXPECT_EQ(m[std::string("lights/") + other.name], other.value == e.value ? "1" : "0")
          << e.name << " scene, " << other.name << " count";
    expect_feature(m, e.feature, e.name);
  }
}

// Shape types: each entry of "shapes" by its name, and OBJ meshes ("mesh"), which make triangles.
TEST(Registry, Shapes) {
  std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const std::map<std::string, const char*> shapes = {{"sphere", kSphere},
                                                     {"triangles", kTriangles}};
  for (const TypeEntry<lucent::ShapeType>& e : TypeList<lucent::ShapeType>::entries) {
    auto it = shapes.find(e.name);
    ASSERT_NE(it, shapes.end()) << "no test scene for the shape type '" << e.name << "'";
    const std::string json = R"({"materials": {"m": {"type": "diffuse"}}, "shapes": [)" +
                             with_material(it->second, "m") + "]}";
    lucent::Scene s = lucent::parse_scene(json, "s.json");
    ASSERT_EQ(s.shapes.size(), 1u);
    EXPECT_EQ(s.shapes[0].type, e.value) << e.name;
    EXPECT_TRUE(s.shapes[0].file.empty());
    EXPECT_EQ(s.shapes[0].count, 1u);
    std::map<std::string, std::string> m = info(json);
    EXPECT_EQ(m["shapes"], "1");
    EXPECT_EQ(m[std::string("shapes/") + e.name], "1") << e.name;
    EXPECT_EQ(m["shapes/mesh"], "0");
    expect_feature(m, e.feature, e.name);
  }
  const std::string obj = R"({"shapes": [{"type": "mesh", "file": ")" + dir + "/t.obj\"}]}";
  lucent::Scene s = lucent::parse_scene(obj, "o.json");
  ASSERT_EQ(s.shapes.size(), 1u);
  EXPECT_EQ(s.shapes[0].type, lucent::ShapeType::Triangle);
  EXPECT_EQ(s.shapes[0].file, dir + "/t.obj");
  EXPECT_EQ(info(obj)["shapes/mesh"], "1");
}

// The lookups themselves: names round-trip, unknown names list the valid ones.
TEST(Registry, NameLookups) {
  for (const TypeEntry<lucent::MaterialType>& e : TypeList<lucent::MaterialType>::entries)
    EXPECT_EQ(lucent::parse_type<lucent::MaterialType>(e.name), e.value);
  EXPECT_FALSE(lucent::find_type<lucent::FilterType>("Box"));  // case-sensitive
  try {
    lucent::parse_type<lucent::FilterType>("sinc");
    ADD_FAILURE() << "sinc accepted";
  } catch (const lucent::Error& err) {
    EXPECT_EQ(std::string(err.what()), "unknown filter 'sinc' (expected one of: " +
                                           lucent::type_names<lucent::FilterType>() + ")");
  }
  EXPECT_STREQ(lucent::type_name(static_cast<lucent::LightType>(77)), "unknown");
}

}  // namespace

namespace {

// A program that includes lucent's headers gets the registry's type lists, not the kernel's
// helper macros (LC_ENABLED, LC_PARAMS, LC_SCENE_BUFFERS, ... were defined in every such file),
// and the headers compile clean under a strict consumer's warnings (-Wsign-conversion warned of
// Image::pixel, clang's -Wcomma of types.hpp; the API tester's finds): each compiler found checks
// a file that includes them all, as tests/package's consumer does in the installed tree.
TEST(Registry, PublicHeadersLeaveNoKernelMacrosAndCompileCleanUnderStrictWarnings) {
  const std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/consumer.cpp", R"(#include <lucent/lucent.hpp>
#if defined(LC_ENABLED) || defined(LC_ENABLED_1) || defined(LC_ON_1) || defined(LC_PARAMS) || \
    defined(LC_OTHER_FEATURES) || defined(LC_SCENE_BUFFERS) || defined(LUCENT_REGISTRY_TYPES_ONLY)
#error "a kernel helper macro of the registry is defined"
#endif
#ifndef LC_MATERIAL_TYPES
#error "no type lists"
#endif
int main() {
  lucent::Image image{1, 1, {0.5f, 0.5f, 0.5f}};
  return image.pixel(0, 0)[0] > 0 && lucent::is_shape_light(lucent::LightType::Sphere) ? 0 : 1;
}
)");
  int compilers = 0;
  for (const std::string cxx : {"g++", "clang++"}) {
    if (std::system(("command -v " + cxx + " >/dev/null 2>&1").c_str()) != 0) continue;
    ++compilers;
    const std::string log = dir + "/" + cxx + ".log";
    const std::string cmd =
        cxx + " -std=c++17 -fsyntax-only -Wall -Wextra -Wpedantic -Wshadow -Wsign-conversion " +
        (cxx == "clang++" ? "-Wcomma " : "") +
        "-Werror -I'" LUCENT_SOURCE_DIR "/include' -I'" LUCENT_BINARY_DIR "/generated/include' '" +
        dir + "/consumer.cpp' >'" + log + "' 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cxx << ":\n" << lucent::test::read_file(log);
  }
  if (compilers == 0) GTEST_SKIP() << "neither g++ nor clang++ is installed";
}

}  // namespace

}  // namespace test_registry
