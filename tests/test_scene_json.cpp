// The JSON scene loader: every validation error names the file and the JSON pointer of the
// problem (or line:column for syntax errors), and the full format parses to what it says.
#include <gtest/gtest.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>
#include <string>

#include "lucent/reference.hpp"
#include "lucent/scene_builder.hpp"
#include "render/pack.hpp"
#include "scene/validate.hpp"
#include "support.hpp"

namespace test_scene_json {

namespace {

using lucent::Scene;

/// The message of the lucent::Error that parsing `json` as "scene.json" throws, or "" if none.
std::string error_of(const std::string& json) {
  try {
    lucent::parse_scene(json, "scene.json");
  } catch (const lucent::Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("unexpected exception type: ") + e.what();
  }
  return "";
}

/// A scene with one diffuse material "m" and the given extra top-level members.
std::string with_material(const std::string& extra) {
  return R"({"materials": {"m": {"type": "diffuse"}})" + (extra.empty() ? "" : ", " + extra) + "}";
}

/// A scene with one triangle list whose transform is `transform` (a JSON array).
std::string with_transform(const std::string& transform) {
  return with_material(R"("shapes": [{"type": "triangles", "material": "m",
      "positions": [[0,0,0],[1,0,0],[0,1,0]], "indices": [0,1,2], "transform": )" +
                       transform + "}]");
}

// Starts with `prefix`: for messages whose tail (an allowed-values list, a library's wording)
// may grow.
#define EXPECT_STARTS_WITH(s, prefix) \
  EXPECT_EQ(std::string(s).substr(0, std::string(prefix).size()), std::string(prefix)) << (s)

// ---------------------------------------------------------------------------------------------
// Syntax

TEST(SceneJson, SyntaxErrorGivesLineAndColumn) {
  // the second comma on line 3 is at column 17
  std::string e = error_of("{\n  \"film\": {\"width\": 3,\n    \"height\": 4,,\n  }\n}");
  EXPECT_STARTS_WITH(e, "scene.json:3:17: invalid JSON: syntax error");
}

TEST(SceneJson, TruncatedFileGivesLineAndColumn) {
  std::string e = error_of("{\"film\": {\"width\": 3,\n  \"height\": 4\n");
  EXPECT_STARTS_WITH(e, "scene.json:3:1: invalid JSON: syntax error");
  EXPECT_NE(e.find("end of input"), std::string::npos) << e;
}

TEST(SceneJson, EmptyFileIsASyntaxError) {
  EXPECT_STARTS_WITH(error_of(""), "scene.json:1:1: invalid JSON: syntax error");
}

TEST(SceneJson, RootMustBeAnObject) {
  EXPECT_EQ(error_of("[1, 2]"), "scene.json: /: must be an object, got an array");
}

// ---------------------------------------------------------------------------------------------
// Wrong types

TEST(SceneJson, WrongTypeInteger) {
  EXPECT_EQ(error_of(R"({"film": {"width": "512"}})"),
            "scene.json: /film/width: must be an integer, got a string \"512\"");
  EXPECT_EQ(error_of(R"({"film": {"height": 1.5}})"),
            "scene.json: /film/height: must be an integer, got a number 1.5");
  EXPECT_EQ(error_of(R"({"integrator": {"spp": true}})"),
            "scene.json: /integrator/spp: must be an integer, got a boolean true");
}

TEST(SceneJson, WrongTypeNumberAndVector) {
  EXPECT_EQ(error_of(R"({"camera": {"fov": "wide"}})"),
            "scene.json: /camera/fov: must be a number, got a string \"wide\"");
  EXPECT_EQ(error_of(R"({"camera": {"position": [0, 1]}})"),
            "scene.json: /camera/position: must be an array of 3 numbers, got an array [0,1]");
  EXPECT_EQ(error_of(R"({"camera": {"position": [0, null, 1]}})"),
            "scene.json: /camera/position/1: must be a number, got null");
  EXPECT_EQ(error_of(R"({"integrator": {"spp": null}})"),
            "scene.json: /integrator/spp: must be an integer, got null");
  EXPECT_EQ(error_of(R"({"integrator": {"type": null}})"),
            "scene.json: /integrator/type: must be a string, got null");
  EXPECT_EQ(error_of(R"({"materials": {"m": {"type": "diffuse", "albedo": "red"}}})"),
            "scene.json: /materials/m/albedo: must be an array of 3 numbers, got a string \"red\"");
}

TEST(SceneJson, WrongTypeContainers) {
  EXPECT_EQ(error_of(R"({"camera": [0, 0, 5]})"),
            "scene.json: /camera: must be an object, got an array");
  EXPECT_EQ(error_of(R"({"materials": [{"type": "diffuse"}]})"),
            "scene.json: /materials: must be an object, got an array");
  EXPECT_EQ(error_of(R"({"shapes": {"type": "sphere"}})"),
            "scene.json: /shapes: must be an array, got an object");
  EXPECT_EQ(error_of(R"({"lights": "sun"})"),
            "scene.json: /lights: must be an array, got a string");
  EXPECT_EQ(error_of(with_material(R"("shapes": [{"type": "sphere", "center": [0,0,0],
                                      "radius": 1, "material": 0}])")),
            "scene.json: /shapes/0/material: must be a string, got a number 0");
}

// ---------------------------------------------------------------------------------------------
// Unknown keys and missing fields

TEST(SceneJson, UnknownKeys) {
  EXPECT_STARTS_WITH(error_of(R"({"shape": []})"), "scene.json: /shape: unknown key (allowed: ");
  EXPECT_STARTS_WITH(error_of(R"({"camera": {"fov_deg": 40}})"),
                     "scene.json: /camera/fov_deg: unknown key (allowed: ");
  // a key that another material type has: roughness is not a diffuse parameter
  EXPECT_STARTS_WITH(error_of(R"({"materials": {"m": {"type": "diffuse", "roughness": 0.2}}})"),
                     "scene.json: /materials/m/roughness: unknown key (allowed: ");
  EXPECT_STARTS_WITH(error_of(with_material(R"("shapes": [{"type": "sphere", "center": [0,0,0],
                                               "radus": 1, "material": "m"}])")),
                     "scene.json: /shapes/0/radus: unknown key (allowed: ");
}

// The place is a JSON pointer (RFC 6901): a key's '~' is written "~0" and its '/' "~1". Keys were
// written raw, so the material "a/b" was reported as "/materials/a/b/ior", a pointer to the
// member "b" of a material "a". Each message's pointer leads back to the element in the file.
TEST(SceneJson, PointersEscapeSlashAndTilde) {
  auto pointer_of = [](const std::string& json) {
    const std::string e = error_of(json);
    const std::size_t a = std::string("scene.json: ").size(), b = e.find(": ", a);
    EXPECT_EQ(e.substr(0, a), "scene.json: ") << e;
    const std::string p = e.substr(a, b - a);
    EXPECT_TRUE(nlohmann::json::parse(json).contains(nlohmann::json::json_pointer(p))) << e;
    return p;
  };
  EXPECT_EQ(pointer_of(R"({"materials": {"a/b~1": {"type": "dielectric", "ior": 0}}})"),
            "/materials/a~1b~01/ior");
  EXPECT_EQ(pointer_of(R"({"materials": {"~/": {"type": "diffuse", "ro/ugh": 0}}})"),
            "/materials/~0~1/ro~1ugh");
  EXPECT_EQ(pointer_of(R"({"camera": {"up/": [0, 1, 0]}})"), "/camera/up~1");
  EXPECT_EQ(pointer_of(with_transform(R"([{"sh/ear": [1, 0, 0]}])")),
            "/shapes/0/transform/0/sh~1ear");
  // a built scene's names too (SceneBuilder::add_material and validate_scene)
  lucent::Material m;
  m.name = "wood/oak";
  m.ior = 0;
  m.type = lucent::MaterialType::Dielectric;
  lucent::SceneBuilder b("built");
  try {
    b.add_material(m);
    ADD_FAILURE() << "ior 0 accepted";
  } catch (const lucent::Error& e) {
    EXPECT_STARTS_WITH(e.what(), "built: /materials/wood~1oak/ior: must be in [");
  }
  Scene s;
  s.path = "built";
  s.materials.push_back(m);
  try {
    lucent::scene_detail::validate_scene(s);
    ADD_FAILURE() << "ior 0 accepted";
  } catch (const lucent::Error& e) {
    EXPECT_STARTS_WITH(e.what(), "built: /materials/wood~1oak/ior: must be in [");
  }
}

TEST(SceneJson, MissingFields) {
  EXPECT_EQ(error_of(with_material(
                R"("shapes": [{"type": "sphere", "center": [0,0,0], "material": "m"}])")),
            "scene.json: /shapes/0: missing required field 'radius'");
  EXPECT_EQ(error_of(R"({"materials": {"m": {"albedo": [1, 1, 1]}}})"),
            "scene.json: /materials/m: missing required field 'type'");
  EXPECT_EQ(error_of(with_material(R"("shapes": [{"type": "triangles", "material": "m",
                                      "positions": [[0,0,0],[1,0,0],[0,1,0]]}])")),
            "scene.json: /shapes/0: missing required field 'indices'");
  EXPECT_EQ(error_of(R"({"lights": [{"type": "point", "intensity": [1, 1, 1]}]})"),
            "scene.json: /lights/0: missing required field 'position'");
  // an environment takes radiance or file: the message names both (it named radiance alone)
  EXPECT_EQ(error_of(R"({"lights": [{"type": "environment"}]})"),
            "scene.json: /lights/0: missing required field 'radiance' (or 'file', a map)");
  EXPECT_EQ(error_of(R"({"shapes": [{"center": [0, 0, 0]}]})"),
            "scene.json: /shapes/0: missing required field 'type'");
}

// ---------------------------------------------------------------------------------------------
// Values out of their domain

TEST(SceneJson, NegativeRadiusNamesTheShape) {
  std::string spheres;
  for (int i = 0; i < 3; ++i)
    spheres += R"({"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}, )";
  std::string bad = R"({"type": "sphere", "center": [0, 0, 0], "radius": -1, "material": "m"})";
  EXPECT_EQ(error_of(with_material("\"shapes\": [" + spheres + bad + "]")),
            "scene.json: /shapes/3/radius: must be > 0, got -1");
  EXPECT_EQ(error_of(with_material(R"("shapes": [{"type": "sphere", "center": [0,0,0],
                                      "radius": 0, "material": "m"}])")),
            "scene.json: /shapes/0/radius: must be > 0, got 0");
}

TEST(SceneJson, OtherDomainErrors) {
  EXPECT_EQ(error_of(R"({"camera": {"fov": 180}})"),
            "scene.json: /camera/fov: must be in (0, 180) degrees, got 180");
  EXPECT_EQ(error_of(R"({"camera": {"position": [1, 2, 3], "look_at": [1, 2, 3]}})"),
            "scene.json: /camera/look_at: must differ from the camera position");
  EXPECT_EQ(error_of(R"({"camera": {"position": [0, 5, 0], "look_at": [0, 0, 0]}})"),
            "scene.json: /camera/up: must not be parallel to the viewing direction");
  EXPECT_EQ(error_of(R"({"camera": {"up": [0, 0, 0]}})"),
            "scene.json: /camera/up: must be a non-zero vector");
  EXPECT_EQ(error_of(R"({"camera": {"aperture": -0.5}})"),
            "scene.json: /camera/aperture: must be >= 0, got -0.5");
  // a lens far wider than the focus distance: its rays missed the focal plane in float, and the
  // geometry vanished from the image (aperture 1e9 at 6 units)
  EXPECT_EQ(
      error_of(R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "aperture": 501}})"),
      "scene.json: /camera/aperture: must be at most 100 times the focus distance (5), got "
      "501");
  EXPECT_EQ(error_of(R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "aperture": 501,
                                    "focus_distance": 10}})"),
            "");
  EXPECT_EQ(error_of(R"({"materials": {"m": {"type": "diffuse", "albedo": [0.5, -0.1, 0]}}})"),
            "scene.json: /materials/m/albedo/1: must be >= 0, got -0.1");
  EXPECT_EQ(error_of(R"({"materials": {"m": {"type": "conductor", "roughness": 1.5}}})"),
            "scene.json: /materials/m/roughness: must be in [0, 1], got 1.5");
  EXPECT_EQ(error_of(R"({"materials": {"m": {"type": "dielectric", "ior": 0}}})"),
            "scene.json: /materials/m/ior: must be in [0.05, 20], got 0");
  EXPECT_EQ(error_of(R"({"materials": {"": {"type": "diffuse"}}})"),
            "scene.json: /materials/: material names must not be empty");
  EXPECT_EQ(error_of(R"({"lights": [{"type": "environment", "radiance": [1, 1, 1]},
                                    {"type": "environment", "radiance": [1, 1, 1]}]})"),
            "scene.json: /lights/1: only one environment light is allowed");
  EXPECT_EQ(error_of(R"({"lights": [{"type": "environment", "radiance": [1,1,1], "scale": 2}]})"),
            "scene.json: /lights/0/scale: only allowed with file");
  EXPECT_EQ(error_of(R"({"film": {"filter": {"type": "gaussian", "radius": -2}}})"),
            "scene.json: /film/filter/radius: must be > 0, got -2");
}

TEST(SceneJson, TriangleListErrors) {
  auto tri = [](const std::string& body) {
    return error_of(
        with_material(R"("shapes": [{"type": "triangles", "material": "m", )" + body + "}]"));
  };
  EXPECT_EQ(tri(R"("positions": [[0,0,0],[1,0,0],[0,1,0]], "indices": [0,1,3])"),
            "scene.json: /shapes/0/indices/2: must be in [0, 2], got 3");
  EXPECT_EQ(
      tri(R"("positions": [[0,0,0],[1,0,0],[0,1,0]], "indices": [0,1])"),
      "scene.json: /shapes/0/indices: must be a non-empty array whose length is a multiple of 3");
  // an empty index list made a shape of no triangle without a word
  EXPECT_EQ(tri(R"("positions": [[0,0,0],[1,0,0],[0,1,0]], "indices": [])"),
            "scene.json: /shapes/0/indices: must be a non-empty array whose length is a multiple "
            "of 3");
  EXPECT_EQ(tri(R"("positions": [], "indices": [])"),
            "scene.json: /shapes/0/positions: must be a non-empty array of [x, y, z]");
  EXPECT_EQ(tri(R"("positions": [[0,0,0],[1,0,0],[0,1,0]], "indices": [0,1,2],
                   "normals": [[0,0,1],[0,0,1]])"),
            "scene.json: /shapes/0/normals: must have one entry per position (3), got 2");
  EXPECT_EQ(tri(R"("positions": [[0,0,0],[1,0,0],[0,1,0]], "indices": [0,1,2],
                   "uvs": [[0,0],[1,0],[0,1,2]])"),
            "scene.json: /shapes/0/uvs/2: must be an array of 2 numbers");
  EXPECT_EQ(tri(R"("positions": [[0,0,0],[1,0,"x"],[0,1,0]], "indices": [0,1,2])"),
            "scene.json: /shapes/0/positions/1/2: must be a number, got a string \"x\"");
}

// ---------------------------------------------------------------------------------------------
// NaN and infinities

TEST(SceneJson, NanAndInfinityAsStrings) {
  for (const char* s : {"NaN", "nan", "Infinity", "inf", "-Infinity", "-inf"}) {
    EXPECT_EQ(error_of(std::string(R"({"camera": {"fov": ")") + s + "\"}}"),
              std::string("scene.json: /camera/fov: must be a finite number, got ") + s);
  }
  EXPECT_EQ(error_of(with_material(R"("shapes": [{"type": "sphere", "center": [0, "NaN", 0],
                                      "radius": 1, "material": "m"}])")),
            "scene.json: /shapes/0/center/1: must be a finite number, got NaN");
}

TEST(SceneJson, HugeLiteralsAreReportedWithLineAndColumn) {
  // 1e999 overflows a double: the JSON library rejects it while parsing, before any pointer
  // exists, so the place is given as line:column of the literal.
  EXPECT_EQ(error_of("{\"integrator\":\n {\"spp\": 1e999}}"),
            "scene.json:2:10: number out of range (not a finite double): 1e999");
  EXPECT_EQ(error_of(R"({"camera": {"fov": -1e999}})"),
            "scene.json:1:20: number out of range (not a finite double): -1e999");
}

// ---------------------------------------------------------------------------------------------
// Names and enumerations

TEST(SceneJson, UnknownMaterialName) {
  EXPECT_EQ(error_of(with_material(R"("shapes": [{"type": "sphere", "center": [0,0,0],
                                      "radius": 1, "material": "gold"}])")),
            "scene.json: /shapes/0/material: unknown material 'gold'");
  EXPECT_EQ(error_of(with_material(R"("shapes": [{"type": "triangles", "material": "Gold",
      "positions": [[0,0,0],[1,0,0],[0,1,0]], "indices": [0,1,2]}])")),
            "scene.json: /shapes/0/material: unknown material 'Gold'");
}

TEST(SceneJson, BadEnumValues) {
  EXPECT_STARTS_WITH(error_of(R"({"film": {"filter": {"type": "sinc"}}})"),
                     "scene.json: /film/filter/type: unknown value 'sinc' (expected one of: box");
  EXPECT_STARTS_WITH(error_of(R"({"film": {"transfer": "rec709"}})"),
                     "scene.json: /film/transfer: unknown value 'rec709' (expected one of: ");
  EXPECT_STARTS_WITH(error_of(R"({"film": {"tonemap": "filmic"}})"),
                     "scene.json: /film/tonemap: unknown value 'filmic' (expected one of: ");
  EXPECT_STARTS_WITH(error_of(R"({"integrator": {"type": "bdpt"}})"),
                     "scene.json: /integrator/type: unknown value 'bdpt' (expected one of: ");
  EXPECT_STARTS_WITH(error_of(R"({"materials": {"m": {"type": "velvet"}}})"),
                     "scene.json: /materials/m/type: unknown value 'velvet' (expected one of: ");
  EXPECT_STARTS_WITH(error_of(R"({"shapes": [{"type": "cube"}]})"),
                     "scene.json: /shapes/0/type: unknown value 'cube' (expected one of: ");
  EXPECT_STARTS_WITH(error_of(R"({"lights": [{"type": "spot"}]})"),
                     "scene.json: /lights/0/type: unknown value 'spot' (expected one of: ");
  // enumerations are case-sensitive
  EXPECT_STARTS_WITH(error_of(R"({"integrator": {"type": "Path"}})"),
                     "scene.json: /integrator/type: unknown value 'Path'");
  // the lists are the registries' names (lucent/types.hpp); shapes add OBJ meshes, lights leave
  // out the emissive shapes' types
  EXPECT_EQ(error_of(R"({"shapes": [{"type": "cube"}]})"),
            "scene.json: /shapes/0/type: unknown value 'cube' (expected one of: " +
                lucent::type_names<lucent::ShapeType>() + ", mesh)");
  EXPECT_EQ(error_of(R"({"lights": [{"type": "spot"}]})"),
            "scene.json: /lights/0/type: unknown value 'spot' (expected one of: point, "
            "environment, environment_map)");
  EXPECT_EQ(error_of(R"({"integrator": {"type": "bdpt"}})"),
            "scene.json: /integrator/type: unknown value 'bdpt' (expected one of: " +
                lucent::type_names<lucent::IntegratorType>() + ")");
}

TEST(SceneJson, EnvironmentLights) {
  std::string dir = lucent::test::temp_dir();
  lucent::write_image(dir + "/sky.pfm", lucent::Image{2, 1, std::vector<float>(6, 0.25f)});
  // "environment" with "file" and "environment_map" are the same light
  for (const char* type : {"environment", "environment_map"}) {
    Scene s = lucent::parse_scene(std::string(R"({"lights": [{"type": ")") + type +
                                      R"(", "file": ")" + dir + R"(/sky.pfm", "scale": 2}]})",
                                  "scene.json");
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].type, lucent::LightType::EnvironmentMap);
    EXPECT_EQ(s.lights[0].radiance, glm::dvec3(2.0));
    ASSERT_EQ(s.textures.size(), 1u);
    EXPECT_EQ(s.lights[0].texture, 0);
  }
  EXPECT_EQ(error_of(R"({"lights": [{"type": "environment_map", "scale": 2}]})"),
            "scene.json: /lights/0: missing required field 'file'");
  EXPECT_STARTS_WITH(
      error_of(
          R"({"lights": [{"type": "environment_map", "file": "x.pfm", "radiance": [1,1,1]}]})"),
      "scene.json: /lights/0/radiance: unknown key (allowed: ");
  EXPECT_EQ(error_of(R"({"lights": [{"type": "environment_map", "file": ")" + dir +
                     R"(/sky.pfm", "scale": -1}]})"),
            "scene.json: /lights/0/scale: must be >= 0, got -1");
  EXPECT_EQ(error_of(R"({"lights": [{"type": "triangle"}]})"),
            "scene.json: /lights/0/type: 'triangle' lights are emissive shapes, not entries of "
            "\"lights\": give a shape a material with \"emission\"");
}

TEST(SceneJson, OutOfRangeIntegers) {
  EXPECT_EQ(error_of(R"({"film": {"width": 0}})"),
            "scene.json: /film/width: must be in [1, 16384], got 0");
  EXPECT_EQ(error_of(R"({"film": {"height": 16385}})"),
            "scene.json: /film/height: must be in [1, 16384], got 16385");
  EXPECT_EQ(error_of(R"({"integrator": {"spp": 0}})"),
            "scene.json: /integrator/spp: must be in [1, 16777216], got 0");
  EXPECT_EQ(error_of(R"({"integrator": {"max_depth": -3}})"),
            "scene.json: /integrator/max_depth: must be in [1, 100000], got -3");
  EXPECT_EQ(error_of(R"({"integrator": {"seed": -1}})"),
            "scene.json: /integrator/seed: must be in [0, 4294967295], got -1");
  EXPECT_EQ(error_of(R"({"integrator": {"seed": 4294967296}})"),
            "scene.json: /integrator/seed: must be in [0, 4294967295], got 4294967296");
  // beyond the signed 64-bit range: reported as written, not wrapped around to -1
  EXPECT_EQ(error_of(R"({"integrator": {"seed": 18446744073709551615}})"),
            "scene.json: /integrator/seed: must be in [0, 4294967295], got 18446744073709551615");
  EXPECT_EQ(error_of(R"({"film": {"width": 9223372036854775808}})"),
            "scene.json: /film/width: must be in [1, 16384], got 9223372036854775808");
}

TEST(SceneJson, BadTransformSteps) {
  EXPECT_EQ(error_of(with_transform(R"({"scale": 2})")),
            "scene.json: /shapes/0/transform: must be an array of transform steps, got an object");
  EXPECT_EQ(error_of(with_transform(R"([{"scale": 2, "translate": [1, 0, 0]}])")),
            "scene.json: /shapes/0/transform/0: each step must hold exactly one of scale, rotate, "
            "translate, matrix");
  EXPECT_EQ(error_of(with_transform(R"([{"scale": 2}, {"shear": [1, 0, 0]}])")),
            "scene.json: /shapes/0/transform/1/shear: unknown transform step (allowed: scale, "
            "rotate, translate, matrix)");
  EXPECT_EQ(error_of(with_transform(R"([{"scale": [1, 0, 1]}])")),
            "scene.json: /shapes/0/transform/0/scale: must not be zero");
  EXPECT_EQ(error_of(with_transform(R"([{"rotate": {"axis": [0, 1, 0]}}])")),
            "scene.json: /shapes/0/transform/0/rotate: missing required field 'degrees'");
  EXPECT_EQ(error_of(with_transform(R"([{"rotate": {"axis": [0, 0, 0], "degrees": 30}}])")),
            "scene.json: /shapes/0/transform/0/rotate/axis: must be a non-zero vector");
  EXPECT_EQ(error_of(with_transform(R"([{"translate": [1, 2]}])")),
            "scene.json: /shapes/0/transform/0/translate: must be an array of 3 numbers, got an "
            "array [1,2]");
  EXPECT_EQ(error_of(with_transform(R"([{"matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,0]]}])")),
            "scene.json: /shapes/0/transform/0/matrix: must be 4 rows of 4 numbers");
  EXPECT_EQ(error_of(with_transform(R"([{"matrix": [[1,0,0,0],[0,1,0],[0,0,1,0],[0,0,0,1]]}])")),
            "scene.json: /shapes/0/transform/0/matrix/1: must be a row of 4 numbers");
  EXPECT_EQ(error_of(with_transform(R"([{"matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,1,1]]}])")),
            "scene.json: /shapes/0/transform/0/matrix: the last row must be [0, 0, 0, 1] (affine "
            "transforms only)");
  EXPECT_EQ(error_of(with_transform(R"([{"matrix": [[1,0,0,0],[2,0,0,0],[0,0,1,0],[0,0,0,1]]}])")),
            "scene.json: /shapes/0/transform/0/matrix: must be invertible");
  // nearly parallel columns: singular in all but name
  EXPECT_EQ(
      error_of(with_transform(R"([{"matrix": [[1,1,0,0],[0,1e-14,0,0],[0,0,1,0],[0,0,0,1]]}])")),
      "scene.json: /shapes/0/transform/0/matrix: must be invertible");
  EXPECT_EQ(
      error_of(with_transform(R"([{"matrix": [[1,0,0,"inf"],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}])")),
      "scene.json: /shapes/0/transform/0/matrix/0/3: must be a finite number, got inf");
}

TEST(SceneJson, LoadSceneNamesTheFile) {
  std::string dir = lucent::test::temp_dir();
  try {
    lucent::load_scene(dir + "/missing.json");
    FAIL() << "no error for a missing file";
  } catch (const lucent::Error& e) {
    EXPECT_STARTS_WITH(e.what(), dir + "/missing.json: cannot open scene file");
  }
  try {
    lucent::load_scene(dir);
    FAIL() << "no error for a directory";
  } catch (const lucent::Error& e) {
    EXPECT_EQ(std::string(e.what()), dir + ": is a directory, not a scene file");
  }
  lucent::test::write_file(dir + "/bad.json", R"({"film": {"width": -4}})");
  try {
    lucent::load_scene(dir + "/bad.json");
    FAIL() << "no error for a bad scene";
  } catch (const lucent::Error& e) {
    EXPECT_EQ(std::string(e.what()), dir + "/bad.json: /film/width: must be in [1, 16384], got -4");
  }
}

// A mesh or texture that cannot be loaded: the scene file and the JSON pointer, then the loader's
// own message naming the file it could not read.
TEST(SceneJson, MissingMeshAndTextureFiles) {
  std::string dir = lucent::test::temp_dir();
  std::string e = error_of(with_material(R"("shapes": [{"type": "sphere", "center": [0,0,0],
      "radius": 1, "material": "m"}, {"type": "mesh", "file": ")" +
                                         dir + R"(/nope.obj"}])"));
  EXPECT_STARTS_WITH(e, "scene.json: /shapes/1/file: " + dir + "/nope.obj: ");
  e = error_of(R"({"materials": {"m": {"type": "diffuse", "albedo": {"texture": ")" + dir +
               R"(/nope.png"}}}})");
  EXPECT_STARTS_WITH(e, "scene.json: /materials/m/albedo/texture: " + dir + "/nope.png: ");
  // relative paths are taken from the scene file's directory
  lucent::test::write_file(dir + "/scene.json",
                           R"({"shapes": [{"type": "mesh", "file": "m.obj"}]})");
  try {
    lucent::load_scene(dir + "/scene.json");
    FAIL() << "no error for a missing mesh";
  } catch (const lucent::Error& ex) {
    EXPECT_STARTS_WITH(ex.what(), dir + "/scene.json: /shapes/0/file: " + dir + "/m.obj: ");
  }
}

// A texture reference's mapping: "wrap" (a mode, or [u, v]), "uv_scale" and "uv_offset"
// ([u, v]; the lookup reads uv * uv_scale + uv_offset). Bad values are one-line errors at their
// place, the same from a file and from SceneBuilder (docs/rendering-model.md, "Textures").
TEST(SceneJson, TextureMappingIsReadAndBadValuesAreErrors) {
  const std::string dir = lucent::test::temp_dir();
  lucent::write_image(dir + "/t.pfm", lucent::Image{2, 1, std::vector<float>(6, 0.5f)});
  auto scene = [&](const std::string& mapping) {
    return R"({"materials": {"m": {"type": "diffuse", "albedo": {"texture": ")" + dir +
           R"(/t.pfm")" + mapping + "}}}}";
  };
  using W = lucent::TextureWrap;
  Scene s = lucent::parse_scene(
      scene(R"(, "wrap": ["mirror", "clamp"], "uv_scale": [2, -0.5], "uv_offset": [0.25, 3])"),
      "scene.json");
  const lucent::Material& m = s.materials.at(0);
  EXPECT_EQ(m.albedo_wrap_u, W::Mirror);
  EXPECT_EQ(m.albedo_wrap_v, W::Clamp);
  EXPECT_EQ(m.albedo_uv_scale, glm::dvec2(2, -0.5));
  EXPECT_EQ(m.albedo_uv_offset, glm::dvec2(0.25, 3));
  s = lucent::parse_scene(scene(R"(, "wrap": "clamp")"), "scene.json");
  EXPECT_EQ(s.materials.at(0).albedo_wrap_u, W::Clamp);
  EXPECT_EQ(s.materials.at(0).albedo_wrap_v, W::Clamp);
  s = lucent::parse_scene(scene(""), "scene.json");  // the defaults: repeat, uv as given
  EXPECT_TRUE(s.materials.at(0).default_albedo_mapping());
  EXPECT_EQ(s.materials.at(0).albedo_uv_scale, glm::dvec2(1, 1));

  const std::string at = "scene.json: /materials/m/albedo/";
  EXPECT_EQ(error_of(scene(R"(, "wrap": "border")")),
            at + "wrap: unknown value 'border' (expected one of: repeat, clamp, mirror)");
  EXPECT_EQ(error_of(scene(R"(, "wrap": ["repeat"])")),
            at + "wrap: must be a wrap mode or [u, v] of two, got an array of 1");
  EXPECT_EQ(error_of(scene(R"(, "wrap": 1)")),
            at + "wrap: must be a wrap mode or [u, v] of two, got a number 1");
  EXPECT_EQ(error_of(scene(R"(, "wrap": ["repeat", "mirrored"])")),
            at + "wrap/1: unknown value 'mirrored' (expected one of: repeat, clamp, mirror)");
  EXPECT_EQ(error_of(scene(R"(, "uv_scale": [0, 1])")),
            at + "uv_scale/0: must be between 1e-06 and 1e+06 in magnitude (either sign), "
                 "got 0");
  EXPECT_EQ(error_of(scene(R"(, "uv_scale": [1, -1e7])")),
            at + "uv_scale/1: must be between 1e-06 and 1e+06 in magnitude (either sign), "
                 "got -1e+07");
  EXPECT_EQ(error_of(scene(R"(, "uv_offset": [0, -2e6])")),
            at + "uv_offset/1: must be at most 1e+06 in magnitude, got -2e+06");
  for (const char* bad : {R"(, "uv_scale": [1])", R"(, "uv_offset": "x")",
                          R"(, "uv_scale": [1, "nan"])", R"(, "wrap": 1)", R"(, "scale": 2)"}) {
    const std::string e = error_of(scene(bad));
    EXPECT_STARTS_WITH(e, at) << bad;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
  // a scene built in code: the same places
  lucent::SceneBuilder b("scene.json");
  lucent::Material bad;
  bad.name = "m";
  bad.albedo_uv_scale = {std::nan(""), 1};
  EXPECT_EQ(lucent::test::error_of([&] { b.add_material(bad); }),
            at + "uv_scale/0: must be a finite number, got nan");
  bad.albedo_uv_scale = {1, 1};
  bad.albedo_wrap_v = static_cast<W>(7);
  EXPECT_EQ(lucent::test::error_of([&] { b.add_material(bad); }),
            at + "wrap/1: unknown wrap mode 7 (expected one of: repeat, clamp, mirror)");
}

// "gamma" without "transfer": "gamma" changed nothing: the default srgb transfer was used.
TEST(SceneJson, GammaNeedsTheGammaTransfer) {
  EXPECT_EQ(error_of(R"({"film": {"gamma": 2.4}})"),
            "scene.json: /film/gamma: only used with \"transfer\": \"gamma\" (the transfer is "
            "srgb)");
  EXPECT_EQ(error_of(R"({"film": {"transfer": "linear", "gamma": 1.8}})"),
            "scene.json: /film/gamma: only used with \"transfer\": \"gamma\" (the transfer is "
            "linear)");
  EXPECT_EQ(
      lucent::parse_scene(R"({"film": {"gamma": 1.8, "transfer": "gamma"}})", "s.json").film.gamma,
      1.8);
}

// A mesh's "material": "" was taken as no material, the OBJ file's own used instead (an
// obj:default diffuse for a file without MTL), where a sphere or a triangle list refuses it.
TEST(SceneJson, EmptyMeshMaterialIsRefused) {
  std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_EQ(error_of(with_material(R"("shapes": [{"type": "mesh", "file": ")" + dir +
                                   R"(/t.obj", "material": ""}])")),
            "scene.json: /shapes/0/material: must name a material, got an empty string (leave it "
            "out to use the OBJ file's materials)");
  EXPECT_EQ(error_of(with_material(R"("shapes": [{"type": "sphere", "center": [0, 0, 0],
                                      "radius": 1, "material": ""}])")),
            "scene.json: /shapes/0/material: unknown material ''");
}

// An empty file name was taken as the scene's directory: "": ".: is a directory, not a texture",
// a message naming a file the scene does not name.
TEST(SceneJson, EmptyFileNamesAreRefused) {
  EXPECT_EQ(error_of(R"({"materials": {"m": {"type": "diffuse", "albedo": {"texture": ""}}}})"),
            "scene.json: /materials/m/albedo/texture: must be a file name, got an empty string");
  EXPECT_EQ(error_of(R"({"shapes": [{"type": "mesh", "file": ""}]})"),
            "scene.json: /shapes/0/file: must be a file name, got an empty string");
  EXPECT_EQ(error_of(R"({"lights": [{"type": "environment", "file": ""}]})"),
            "scene.json: /lights/0/file: must be a file name, got an empty string");
  EXPECT_EQ(error_of(R"({"lights": [{"type": "environment_map", "file": ""}]})"),
            "scene.json: /lights/0/file: must be a file name, got an empty string");
}

// "\u0000" is valid JSON. A path holding one opened the file named by what precedes it
// ("sky.pfm\u0000junk.exr" loaded sky.pfm, exit 0), and the messages that quoted it stopped there.
TEST(SceneJson, StringsWithANulCharacterAreRefused) {
  std::string dir = lucent::test::temp_dir();
  lucent::write_image(dir + "/sky.pfm", lucent::Image{2, 1, std::vector<float>(6, 0.5f)});
  EXPECT_EQ(
      error_of(R"({"lights": [{"type": "environment", "file": ")" + dir +
               R"(/sky.pfm\u0000junk.exr"}]})"),
      "scene.json: /lights/0/file: must not contain a NUL character (\\u0000), at character " +
          std::to_string(dir.size() + 8));
  EXPECT_EQ(error_of(R"({"integrator": {"type": "pa\u0000th"}})"),
            "scene.json: /integrator/type: must not contain a NUL character (\\u0000), at "
            "character 2");
  // keys too: a material's name, or a key whose error was cut off at the NUL
  EXPECT_EQ(error_of(R"({"materials": {"red\u0000junk": {"type": "diffuse"}}})"),
            "scene.json: /materials: the key 'red\\u0000junk' contains a NUL character (\\u0000)");
  EXPECT_EQ(error_of(R"({"film\u0000x": {}})"),
            "scene.json: /: the key 'film\\u0000x' contains a NUL character (\\u0000)");
  // a NUL byte in the text given to parse_scene (not an escape): the parser stopped there and
  // took what came before it, as load_scene refuses such a file
  const std::string text =
      std::string(R"({"film":{"width":8,"height":8}})") + '\0' + R"({"film":{}})";
  EXPECT_EQ(lucent::test::error_of([&] { lucent::parse_scene(text, "mem.json"); }),
            "mem.json: byte 32 is a NUL byte: not a text scene file");
}

// Control characters in an error's message (a user's string) are escaped as the command line
// shows them: a NUL cut the C string of what() off (a device selector "cp\0u" said "device
// 'cp"), and a JSON key, a material's or a file's name with a newline made what() two lines (the
// API campaign). From a file and from a builder alike.
TEST(SceneJson, ErrorsAreOneLineWhateverTheirNamesHold) {
  const lucent::Error e(std::string("a\0b", 3) + " and " + std::string("\0", 1));
  EXPECT_STREQ(e.what(), "a\\x00b and \\x00");
  EXPECT_EQ(error_of(with_material(R"("shapes": [{"type": "sphere", "center": [0,0,0], "radius": 1,
                                       "material": "m", "a\nb": 1}])")),
            "scene.json: /shapes/0/a\\nb: unknown key (allowed: type, center, radius, material)");
  lucent::SceneBuilder b("scene\x1b[31m.json");
  EXPECT_EQ(lucent::test::error_of([&] {
              b.add_sphere({{0, 0, 0}, 1, "no\tsuch"});
            }),
            "scene\\x1b[31m.json: /shapes/0/material: unknown material 'no\\tsuch'");
}

// A setting the file's integrator or camera does not read is said when the file is read (the
// file took rr_depth and mis for whitted, max_depth for direct and a focus_distance with aperture
// 0 without a word; the command line refuses such options). From the file's own keys and
// integrator: a path scene's max_depth rendered with `--integrator direct` is not blamed.
TEST(SceneJson, SettingsThatChangeNothingAreSaid) {
  auto said = [](const std::string& integrator, const std::string& camera = "") {
    lucent::test::CaptureWarnings warnings;
    lucent::parse_scene(R"({"integrator": )" + integrator +
                            R"(, "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0])" + camera +
                            "}}",
                        "scene.json");
    return warnings.all();
  };
  EXPECT_TRUE(said(R"({"type": "path", "max_depth": 5, "rr_depth": 2, "mis": false})").empty());
  EXPECT_TRUE(said(R"({"type": "whitted", "max_depth": 5})").empty());
  // the AOV integrators read none of them, and only ao reads ao_distance (said for the AOVs
  // too: the command line refuses those options for them)
  EXPECT_EQ(said(R"({"type": "ao", "max_depth": 5, "ao_distance": 2})"),
            std::vector<std::string>{"scene.json: /integrator/max_depth: only the path and "
                                     "whitted integrators have it, and this file's integrator is "
                                     "ao: the setting has no effect"});
  EXPECT_EQ(said(R"({"type": "path", "ao_distance": 2})"),
            std::vector<std::string>{"scene.json: /integrator/ao_distance: only the ao "
                                     "integrator has it, and this file's integrator is path: the "
                                     "setting has no effect"});
  EXPECT_EQ(said(R"({"type": "albedo", "clamp": 1, "mis": false})").size(), 2u);
  const std::vector<std::string> whitted =
      said(R"({"type": "whitted", "rr_depth": 2, "mis": true})");
  ASSERT_EQ(whitted.size(), 2u);
  EXPECT_EQ(whitted[0],
            "scene.json: /integrator/rr_depth: only the path integrator has it, and this file's "
            "integrator is whitted: the setting has no effect");
  EXPECT_EQ(said(R"({"type": "direct", "max_depth": 3})").size(), 1u);
  EXPECT_EQ(said(R"({"type": "path"})", R"(, "focus_distance": 3)"),
            std::vector<std::string>{"scene.json: /camera/focus_distance: the aperture is 0 (a "
                                     "pinhole camera, everything in focus): the setting has no "
                                     "effect"});
  EXPECT_TRUE(said(R"({"type": "path"})", R"(, "focus_distance": 5)").empty());  // the look-at's
  EXPECT_TRUE(said(R"({"type": "path"})", R"(, "focus_distance": 3, "aperture": 0.1)").empty());
}

// ---------------------------------------------------------------------------------------------
// The whole format

void expect_vec(const glm::dvec3& got, const glm::dvec3& want, double tol = 1e-12) {
  EXPECT_NEAR(got.x, want.x, tol);
  EXPECT_NEAR(got.y, want.y, tol);
  EXPECT_NEAR(got.z, want.z, tol);
}

TEST(SceneJson, FullFormatParses) {
  const char* text = R"({
    "camera": {"position": [0, 1, 6], "look_at": [0, 1, 0], "up": [0, 1, 0], "fov": 35,
               "roll": 5, "aperture": 0.05, "focus_distance": 5.5},
    "film": {"width": 64, "height": 48, "filter": {"type": "tent", "radius": 1.25},
             "transfer": "gamma", "gamma": 2.4, "exposure": -0.5, "tonemap": "aces"},
    "integrator": {"type": "whitted", "max_depth": 12, "rr_depth": 3, "spp": 7, "seed": 4000000000,
                   "ao_distance": 2.5},
    "materials": {
      "wall":  {"type": "diffuse", "albedo": [0.25, 0.5, 0.75]},
      "lamp":  {"type": "diffuse", "albedo": [0, 0, 0], "emission": [4, 3, 2]},
      "glass": {"type": "dielectric", "ior": 1.33, "tint": [0.9, 1, 0.95]},
      "chrome": {"type": "mirror", "reflectance": [0.8, 0.85, 0.9]},
      "gold":  {"type": "conductor", "specular": [1, 0.78, 0.34], "roughness": 0.2},
      "paint": {"type": "plastic", "albedo": [0.1, 0.2, 0.3], "specular": [0.5, 0.5, 0.5],
                "roughness": 0.05, "ior": 1.6}
    },
    "shapes": [
      {"type": "sphere", "center": [1, 2, 3], "radius": 0.5, "material": "glass"},
      {"type": "triangles", "material": "wall",
       "positions": [[1, 0, 0], [0, 1, 0], [0, 0, 0]], "indices": [2, 0, 1],
       "normals": [[0, 0, 1], [0, 0, 1], [0, 0, 1]], "uvs": [[1, 0], [0, 1], [0, 0]],
       "transform": [{"scale": 2}, {"rotate": {"axis": [0, 0, 3], "degrees": 90}},
                     {"translate": [1, 2, 3]},
                     {"matrix": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 10], [0, 0, 0, 1]]}]},
      {"type": "triangles", "material": "lamp",
       "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "indices": [0, 1, 2],
       "normals": [[0, 0, 1], [0, 0, 1], [0, 0, 1]],
       "transform": [{"matrix": [[-1, 0, 0, 5], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}]},
      {"type": "triangles", "material": "gold",
       "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "indices": [0, 1, 2],
       "normals": [[0, 0, 1], [0, 0, 1], [0, 0, 1]],
       "transform": [{"scale": [1, 1, -1]}]}
    ],
    "lights": [
      {"type": "point", "position": [0, 5, 0], "intensity": [10, 20, 30]},
      {"type": "environment", "radiance": [0.1, 0.2, 0.3]}
    ]
  })";
  Scene s = lucent::parse_scene(text, "full.json");
  EXPECT_EQ(s.path, "full.json");

  expect_vec(s.camera.position, {0, 1, 6});
  expect_vec(s.camera.look_at, {0, 1, 0});
  EXPECT_EQ(s.camera.fov_degrees, 35);
  EXPECT_EQ(s.camera.roll_degrees, 5);
  EXPECT_EQ(s.camera.aperture, 0.05);
  EXPECT_EQ(s.camera.focus_distance, 5.5);

  EXPECT_EQ(s.film.width, 64);
  EXPECT_EQ(s.film.height, 48);
  EXPECT_EQ(s.film.filter.type, lucent::FilterType::Tent);
  EXPECT_EQ(s.film.filter.radius, 1.25);
  EXPECT_EQ(s.film.transfer, lucent::Transfer::Gamma);
  EXPECT_EQ(s.film.gamma, 2.4);
  EXPECT_EQ(s.film.exposure, -0.5);
  EXPECT_EQ(s.film.tonemap, lucent::ToneMap::Aces);

  EXPECT_EQ(s.integrator.type, lucent::IntegratorType::Whitted);
  EXPECT_EQ(s.integrator.max_depth, 12);
  EXPECT_EQ(s.integrator.rr_depth, 3);
  EXPECT_EQ(s.integrator.spp, 7);
  EXPECT_EQ(s.integrator.seed, 4000000000u);
  EXPECT_EQ(s.integrator.ao_distance, 2.5);

  ASSERT_EQ(s.materials.size(), 6u);
  int wall = s.find_material("wall"), lamp = s.find_material("lamp"),
      glass = s.find_material("glass"), chrome = s.find_material("chrome"),
      gold = s.find_material("gold"), paint = s.find_material("paint");
  ASSERT_TRUE(wall >= 0 && lamp >= 0 && glass >= 0 && chrome >= 0 && gold >= 0 && paint >= 0);
  EXPECT_EQ(s.find_material("nothing"), -1);
  EXPECT_EQ(s.materials[wall].type, lucent::MaterialType::Diffuse);
  expect_vec(s.materials[wall].albedo, {0.25, 0.5, 0.75});
  EXPECT_FALSE(s.materials[wall].emissive());
  EXPECT_TRUE(s.materials[lamp].emissive());
  expect_vec(s.materials[lamp].emission, {4, 3, 2});
  EXPECT_EQ(s.materials[glass].type, lucent::MaterialType::Dielectric);
  EXPECT_EQ(s.materials[glass].ior, 1.33);
  expect_vec(s.materials[glass].specular, {0.9, 1, 0.95});
  EXPECT_EQ(s.materials[chrome].type, lucent::MaterialType::Mirror);
  expect_vec(s.materials[chrome].specular, {0.8, 0.85, 0.9});
  EXPECT_EQ(s.materials[gold].type, lucent::MaterialType::Conductor);
  EXPECT_EQ(s.materials[gold].roughness, 0.2);
  expect_vec(s.materials[gold].specular, {1, 0.78, 0.34});
  EXPECT_EQ(s.materials[paint].type, lucent::MaterialType::Plastic);
  expect_vec(s.materials[paint].albedo, {0.1, 0.2, 0.3});
  EXPECT_EQ(s.materials[paint].ior, 1.6);
  EXPECT_EQ(s.materials[paint].roughness, 0.05);

  ASSERT_EQ(s.spheres.size(), 1u);
  expect_vec(s.spheres[0].center, {1, 2, 3});
  EXPECT_EQ(s.spheres[0].radius, 0.5);
  EXPECT_EQ(s.spheres[0].material, glass);

  ASSERT_EQ(s.triangles.size(), 3u);
  ASSERT_EQ(s.positions.size(), 9u);
  ASSERT_EQ(s.normals.size(), 9u);
  ASSERT_EQ(s.uvs.size(), 3u);

  // Steps apply in the order listed: scale 2, rotate 90 degrees about +z, translate (1, 2, 3),
  // then the matrix (a translation by 10 along z, given row by row). By hand:
  // (1,0,0) -> (2,0,0) -> (0,2,0) -> (1,4,3) -> (1,4,13); (0,1,0) -> (0,2,0) -> (-2,0,0) ->
  // (-1,2,3) -> (-1,2,13); (0,0,0) -> (1,2,13).
  const lucent::Triangle& t0 = s.triangles[0];
  EXPECT_EQ(t0.material, wall);
  expect_vec(s.positions[t0.v[0]], {1, 2, 13});
  expect_vec(s.positions[t0.v[1]], {1, 4, 13});
  expect_vec(s.positions[t0.v[2]], {-1, 2, 13});
  for (int k = 0; k < 3; ++k) expect_vec(s.normals[t0.n[k]], {0, 0, 1});
  EXPECT_EQ(s.uvs[t0.uv[0]], glm::dvec2(0, 0));  // indices [2, 0, 1] pick uvs 2, 0, 1
  EXPECT_EQ(s.uvs[t0.uv[1]], glm::dvec2(1, 0));
  EXPECT_EQ(s.uvs[t0.uv[2]], glm::dvec2(0, 1));

  // A mirroring matrix (x -> 5 - x) keeps each face's front: the triangle's geometric normal,
  // (v1 - v0) x (v2 - v0), still agrees with its transformed vertex normals (+z here).
  auto geometric_normal = [&](const lucent::Triangle& t) {
    glm::dvec3 a = s.positions[t.v[0]], b = s.positions[t.v[1]], c = s.positions[t.v[2]];
    return glm::normalize(glm::cross(b - a, c - a));
  };
  const lucent::Triangle& t1 = s.triangles[1];
  EXPECT_EQ(t1.material, lamp);
  std::vector<glm::dvec3> corners = {s.positions[t1.v[0]], s.positions[t1.v[1]],
                                     s.positions[t1.v[2]]};
  for (const glm::dvec3& want : {glm::dvec3(5, 0, 0), glm::dvec3(4, 0, 0), glm::dvec3(5, 1, 0)}) {
    bool found = false;
    for (const glm::dvec3& c : corners) found = found || glm::length(c - want) < 1e-12;
    EXPECT_TRUE(found) << "corner (" << want.x << ", " << want.y << ", " << want.z << ")";
  }
  expect_vec(geometric_normal(t1), {0, 0, 1});
  for (int k = 0; k < 3; ++k) expect_vec(s.normals[t1.n[k]], {0, 0, 1});

  // Mirroring z flips the surface: the normals become -z and the winding follows them.
  const lucent::Triangle& t2 = s.triangles[2];
  expect_vec(geometric_normal(t2), {0, 0, -1});
  for (int k = 0; k < 3; ++k) expect_vec(s.normals[t2.n[k]], {0, 0, -1});

  ASSERT_EQ(s.lights.size(), 2u);
  EXPECT_EQ(s.lights[0].type, lucent::LightType::Point);
  expect_vec(s.lights[0].position, {0, 5, 0});
  expect_vec(s.lights[0].intensity, {10, 20, 30});
  EXPECT_EQ(s.lights[1].type, lucent::LightType::Environment);
  expect_vec(s.lights[1].radiance, {0.1, 0.2, 0.3});
}

// look_at's coordinates are floats, its distance from the camera need not be: the default focus
// distance (the distance to look_at) was that distance, which the render then refused as
// "/camera/focus_distance: must fit in a float", a key the scene does not have (and a pinhole
// does not use). The scene keeps 0 (the distance to look_at); the kernel's camera takes the
// largest float.
TEST(SceneJson, LookAtFartherFromTheCameraThanTheLargestFloat) {
  Scene s = lucent::parse_scene(
      R"({"camera": {"position": [0, 0, 5], "look_at": [-3e38, -1e38, -3e38]},
          "film": {"width": 2, "height": 2}, "integrator": {"spp": 1}})",
      "far.json");
  EXPECT_EQ(s.camera.focus_distance, 0.0);
  EXPECT_EQ(lucent::render_detail::pack_camera(s.camera, 2, 2).focus_distance, FLT_MAX);
  lucent::ReferenceOptions o;
  o.spp = 1;
  EXPECT_NO_THROW(lucent::render_reference(s, o));
}

// A tiny direction is a direction: an up of [0, 1e-170, 0] (or look_at 1e-170 from the camera,
// a rotation axis or a mesh normal of that size) has a squared length that underflows to 0, and
// was refused as "/camera/up: must be a non-zero vector" (glm::normalize made it NaN). Now the
// camera is the one with up [0, 1, 0], to the bit, in the kernel's packed camera and in the
// reference's image.
TEST(SceneJson, TinyDirectionsAreDirections) {
  auto scene = [](const std::string& camera, const std::string& axis, const std::string& normal) {
    return lucent::parse_scene(R"({"camera": )" + camera + R"(,
        "film": {"width": 6, "height": 4}, "integrator": {"spp": 2},
        "materials": {"m": {"type": "diffuse"}},
        "lights": [{"type": "point", "position": [0, 3, 3], "intensity": [5, 5, 5]}],
        "shapes": [{"type": "sphere", "center": [0.3, 0, 0], "radius": 1, "material": "m"},
                   {"type": "triangles", "material": "m", "positions": [[0,0,0],[1,0,0],[0,1,0]],
                    "indices": [0, 1, 2], "normals": [)" +
                                   normal + "," + normal + "," + normal + R"(],
                    "transform": [{"rotate": {"axis": )" +
                                   axis + R"(, "degrees": 30}}]}]})",
                               "tiny.json");
  };
  const Scene want = scene(R"({"position": [0, 0, 5], "look_at": [0, 0, 4], "up": [0, 1, 0]})",
                           "[0, 0, 1]", "[0, 0, 1]");
  for (const char* camera :
       {R"({"position": [0, 0, 5], "look_at": [0, 0, 4], "up": [0, 1e-170, 0]})",
        R"({"position": [0, 0, 1e-170], "look_at": [0, 0, 0]})"}) {
    SCOPED_TRACE(camera);
    Scene s;
    ASSERT_NO_THROW(s = scene(camera, "[0, 0, 1e-170]", "[0, 0, 1e-170]"));
    const lc_camera a = lucent::render_detail::pack_camera(s.camera, 6, 4);
    const lc_camera b = lucent::render_detail::pack_camera(want.camera, 6, 4);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(a.right[k], b.right[k]);
      EXPECT_EQ(a.up[k], b.up[k]);
      EXPECT_EQ(a.forward[k], b.forward[k]);
    }
    ASSERT_EQ(s.normals.size(), want.normals.size());
    for (std::size_t i = 0; i < s.normals.size(); ++i) EXPECT_EQ(s.normals[i], want.normals[i]);
    ASSERT_EQ(s.positions.size(), want.positions.size());
    for (std::size_t i = 0; i < s.positions.size(); ++i)
      EXPECT_EQ(s.positions[i], want.positions[i]);
    if (s.camera.position == want.camera.position) {  // the same pinhole: the same image
      lucent::ReferenceOptions o;
      o.threads = 1;
      const std::vector<float> image = lucent::render_reference(want, o).mean.rgb;
      EXPECT_GT(*std::max_element(image.begin(), image.end()), 0.0f);
      EXPECT_EQ(lucent::render_reference(s, o).mean.rgb, image);
    }
  }
}

// The default focus distance (0: the distance to look_at) follows a camera moved after the scene
// was loaded, as it does in a scene built in code. Loading wrote the distance into the scene, so
// a thin lens moved closer (README's camera-move example) stayed focused at the old distance.
TEST(SceneJson, DefaultFocusFollowsAMovedCamera) {
  Scene s = lucent::parse_scene(
      R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "aperture": 0.1}})", "lens.json");
  EXPECT_EQ(lucent::render_detail::pack_camera(s.camera, 2, 2).focus_distance, 5.0f);
  s.camera.position.z = 2;
  EXPECT_EQ(lucent::render_detail::pack_camera(s.camera, 2, 2).focus_distance, 2.0f);
}

TEST(SceneJson, DefaultsWhenKeysAreLeftOut) {
  Scene s = lucent::parse_scene("{}", "empty.json");
  EXPECT_EQ(s.film.width, 512);
  EXPECT_EQ(s.film.height, 512);
  EXPECT_EQ(s.integrator.type, lucent::IntegratorType::Path);
  EXPECT_TRUE(s.materials.empty());
  EXPECT_TRUE(s.spheres.empty());
  EXPECT_TRUE(s.triangles.empty());
  // focus distance 0: the distance to look_at, whatever the camera's position when rendered
  EXPECT_EQ(s.camera.focus_distance, 0.0);
  // the defaults README.md's "Defaults" paragraph lists
  expect_vec(s.camera.position, {0, 0, 5});
  expect_vec(s.camera.look_at, {0, 0, 0});
  expect_vec(s.camera.up, {0, 1, 0});
  EXPECT_EQ(s.camera.fov_degrees, 45);
  EXPECT_EQ(s.camera.roll_degrees, 0);
  EXPECT_EQ(s.camera.aperture, 0);
  EXPECT_EQ(s.film.filter.type, lucent::FilterType::Box);
  EXPECT_EQ(s.film.transfer, lucent::Transfer::Srgb);
  EXPECT_EQ(s.film.gamma, 2.2);
  EXPECT_EQ(s.film.exposure, 0);
  EXPECT_EQ(s.film.tonemap, lucent::ToneMap::Clamp);
  EXPECT_EQ(s.integrator.max_depth, 8);
  EXPECT_EQ(s.integrator.rr_depth, 4);
  EXPECT_EQ(s.integrator.spp, 16);
  EXPECT_EQ(s.integrator.seed, 0u);
  EXPECT_TRUE(s.integrator.mis);
  EXPECT_EQ(s.integrator.sampler, lucent::SamplerType::Sobol);
  Scene m =
      lucent::parse_scene(R"({"materials": {"d": {"type": "diffuse"}, "p": {"type": "plastic"},
      "mi": {"type": "mirror"}, "g": {"type": "dielectric"}, "c": {"type": "conductor"},
      "r": {"type": "rough_dielectric"}, "dm": {"type": "diffuse_mirror"}}})",
                          "m.json");
  auto mat = [&m](const char* name) { return m.materials[m.find_material(name)]; };
  expect_vec(mat("d").albedo, glm::dvec3(0.8));
  expect_vec(mat("p").albedo, glm::dvec3(0.8));
  expect_vec(mat("dm").albedo, glm::dvec3(0.8));
  expect_vec(mat("dm").specular, glm::dvec3(0.2));
  expect_vec(mat("mi").specular, glm::dvec3(1));
  expect_vec(mat("g").specular, glm::dvec3(1));
  expect_vec(mat("r").specular, glm::dvec3(1));
  expect_vec(mat("c").specular, glm::dvec3(0.9));
  expect_vec(mat("p").specular, glm::dvec3(1));
  for (const char* n : {"g", "p", "r"}) EXPECT_EQ(mat(n).ior, 1.5) << n;
  for (const char* n : {"c", "p", "r"}) EXPECT_EQ(mat(n).roughness, 0.1) << n;
  for (const lucent::Material& x : m.materials) expect_vec(x.emission, glm::dvec3(0));
  // a filter's default radius depends on its type
  EXPECT_EQ(
      lucent::parse_scene(R"({"film": {"filter": {"type": "box"}}})", "f.json").film.filter.radius,
      0.5);
  EXPECT_EQ(lucent::parse_scene(R"({"film": {"filter": {"type": "gaussian"}}})", "f.json")
                .film.filter.radius,
            1.5);
}

// A C++ caller can take the library's warnings, as Python's on_warning does: load_scene,
// parse_scene, SceneBuilder::add_obj (its OBJ and MTL files) and render_reference printed
// "lucent: warning: ..." on stderr, with no way to capture or silence them (the API tester's
// find). A ScopedWarningSink takes them on its thread while it lives (innermost first), and
// ReferenceOptions::on_warning takes render_reference's before it.
TEST(SceneJson, ScopedWarningSinkTakesTheLoadersAndTheReferencesWarnings) {
  lucent::test::CaptureWarnings stderr_sink;  // the process-wide hook: stderr's stand-in
  const std::string dir = lucent::test::temp_dir();
  const std::string text = R"({"camera": {"position": [0, 0, 4], "focus_distance": 3},
    "film": {"width": 4, "height": 4}, "materials": {"w": {"type": "diffuse"}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "w"}]})";
  lucent::test::write_file(dir + "/s.json", text);
  lucent::test::write_file(dir + "/x.obj",
                           "mtllib nothere.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const std::string focus = "/camera/focus_distance: the aperture is 0";
  std::vector<std::string> got;
  Scene scene;
  {
    lucent::ScopedWarningSink sink([&](const std::string& w) { got.push_back(w); });
    scene = lucent::parse_scene(text, "p.json");
    ASSERT_EQ(got.size(), 1u);
    EXPECT_EQ(got[0].find("p.json: " + focus), 0u) << got[0];
    lucent::load_scene(dir + "/s.json");
    ASSERT_EQ(got.size(), 2u);
    EXPECT_EQ(got[1].find(dir + "/s.json: " + focus), 0u) << got[1];
    lucent::SceneBuilder b("built");
    b.add_obj({dir + "/x.obj", glm::dmat4(1.0), ""});
    ASSERT_EQ(got.size(), 3u);
    EXPECT_NE(got[2].find("material library 'nothere.mtl' not found"), std::string::npos) << got[2];
    lucent::ReferenceOptions o;
    o.spp = 1;
    o.threads = 1;
    lucent::render_reference(scene, o);
    ASSERT_EQ(got.size(), 4u);
    EXPECT_NE(got[3].find("the scene has no light"), std::string::npos) << got[3];
    {
      // nested: the inner sink takes them; a null one changes nothing
      std::vector<std::string> inner;
      lucent::ScopedWarningSink inner_sink([&](const std::string& w) { inner.push_back(w); });
      lucent::ScopedWarningSink null_sink(nullptr);
      lucent::parse_scene(text, "p.json");
      EXPECT_EQ(inner.size(), 1u);
    }
    EXPECT_EQ(got.size(), 4u);
    // render_reference's own sink before the thread's
    std::vector<std::string> own;
    o.on_warning = [&](const std::string& w) { own.push_back(w); };
    lucent::render_reference(scene, o);
    EXPECT_EQ(own.size(), 1u);
    EXPECT_EQ(got.size(), 4u);
  }
  EXPECT_TRUE(stderr_sink.all().empty()) << stderr_sink.dump();
  lucent::parse_scene(text, "p.json");  // the scope ended: stderr's again
  EXPECT_EQ(stderr_sink.count(focus), 1) << stderr_sink.dump();
}

}  // namespace

}  // namespace test_scene_json

// (the next file of its unity batch may define its own)
#undef EXPECT_STARTS_WITH
