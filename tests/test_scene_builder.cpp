// Scenes built in code (lucent/scene_builder.hpp): every value check gives the same message for
// a scene built with SceneBuilder and for the same scene written in JSON (one code path checks
// both), a scene built in code equals the same scene loaded from JSON, and textures come from
// memory as they would from an image file.
#include <gtest/gtest.h>
#include <stb/stb_image_write.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <string>
#include <vector>

#include "lucent/lucent.hpp"
#include "lucent/reference.hpp"
#include "support.hpp"

namespace test_scene_builder {

namespace {

using lucent::SceneBuilder;

using lucent::test::error_of;

std::string json_error(const std::string& json) {
  return error_of([&] { lucent::parse_scene(json, "scene.json"); });
}

/// The message of building in code, with the builder named as the JSON file is.
std::string code_error(const std::function<void(SceneBuilder&)>& build) {
  return error_of([&] {
    SceneBuilder b("scene.json");
    build(b);
    b.build();
  });
}

lucent::Material material(const std::string& name, lucent::MaterialType type) {
  lucent::Material m;
  m.name = name;
  m.type = type;
  return m;
}

/// The diffuse material "m" of the JSON cases below.
void add_m(SceneBuilder& b) { b.add_material(material("m", lucent::MaterialType::Diffuse)); }
const char* kM = R"("materials": {"m": {"type": "diffuse"}})";

lucent::MeshShape triangle(const std::string& material = "m") {
  lucent::MeshShape mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.indices = {0, 1, 2};
  mesh.material = material;
  return mesh;
}

struct Case {
  const char* what;
  std::string json;
  std::function<void(SceneBuilder&)> code;
  std::string message;
};

std::vector<Case> cases() {
  using lucent::MaterialType;
  auto camera = [](const std::function<void(lucent::Camera&)>& set) {
    return [set](SceneBuilder& b) {
      lucent::Camera c;
      set(c);
      b.set_camera(c);
    };
  };
  auto film = [](const std::function<void(lucent::Film&)>& set) {
    return [set](SceneBuilder& b) {
      lucent::Film f;
      set(f);
      b.set_film(f);
    };
  };
  auto integrator = [](const std::function<void(lucent::Integrator&)>& set) {
    return [set](SceneBuilder& b) {
      lucent::Integrator in;
      set(in);
      b.set_integrator(in);
    };
  };
  auto mat = [](MaterialType type, const std::function<void(lucent::Material&)>& set) {
    return [type, set](SceneBuilder& b) {
      lucent::Material m = material("m", type);
      set(m);
      b.add_material(m);
    };
  };
  auto mesh = [](const std::function<void(lucent::MeshShape&)>& set) {
    return [set](SceneBuilder& b) {
      add_m(b);
      lucent::MeshShape t = triangle();
      set(t);
      b.add_mesh(t);
    };
  };
  auto tri_json = [](const std::string& body) {
    return std::string("{") + kM + R"(, "shapes": [{"type": "triangles", "material": "m", )" +
           body + "}]}";
  };
  const std::string tri_pos = R"("positions": [[0,0,0],[1,0,0],[0,1,0]], )";
  return {
      {"fov", R"({"camera": {"fov": 180}})", camera([](auto& c) { c.fov_degrees = 180; }),
       "scene.json: /camera/fov: must be in (0, 180) degrees, got 180"},
      {"look_at", R"({"camera": {"position": [1, 2, 3], "look_at": [1, 2, 3]}})",
       camera([](auto& c) {
         c.position = c.look_at = {1, 2, 3};
       }),
       "scene.json: /camera/look_at: must differ from the camera position"},
      {"up parallel", R"({"camera": {"position": [0, 5, 0], "look_at": [0, 0, 0]}})",
       camera([](auto& c) {
         c.position = {0, 5, 0};
         c.look_at = {0, 0, 0};
       }),
       "scene.json: /camera/up: must not be parallel to the viewing direction"},
      {"up zero", R"({"camera": {"up": [0, 0, 0]}})", camera([](auto& c) {
         c.up = {0, 0, 0};
       }),
       "scene.json: /camera/up: must be a non-zero vector"},
      {"aperture", R"({"camera": {"aperture": -0.5}})", camera([](auto& c) { c.aperture = -0.5; }),
       "scene.json: /camera/aperture: must be >= 0, got -0.5"},
      {"focus", R"({"camera": {"focus_distance": -2}})",
       camera([](auto& c) { c.focus_distance = -2; }),
       "scene.json: /camera/focus_distance: must be >= 0, got -2"},
      {"width", R"({"film": {"width": 0}})", film([](auto& f) { f.width = 0; }),
       "scene.json: /film/width: must be in [1, 16384], got 0"},
      {"height", R"({"film": {"height": 16385}})", film([](auto& f) { f.height = 16385; }),
       "scene.json: /film/height: must be in [1, 16384], got 16385"},
      {"radius", R"({"film": {"filter": {"type": "gaussian", "radius": -2}}})", film([](auto& f) {
         f.filter = {lucent::FilterType::Gaussian, -2};
       }),
       "scene.json: /film/filter/radius: must be > 0, got -2"},
      {"radius max", R"({"film": {"filter": {"type": "box", "radius": 9}}})",
       film([](auto& f) { f.filter.radius = 9; }),
       "scene.json: /film/filter/radius: must be <= 8 pixels"},
      {"gamma", R"({"film": {"gamma": 0}})", film([](auto& f) { f.gamma = 0; }),
       "scene.json: /film/gamma: must be > 0, got 0"},
      {"spp", R"({"integrator": {"spp": 0}})", integrator([](auto& in) { in.spp = 0; }),
       "scene.json: /integrator/spp: must be in [1, 16777216], got 0"},
      {"max_depth", R"({"integrator": {"max_depth": -3}})",
       integrator([](auto& in) { in.max_depth = -3; }),
       "scene.json: /integrator/max_depth: must be in [1, 100000], got -3"},
      {"rr_depth", R"({"integrator": {"rr_depth": 100001}})",
       integrator([](auto& in) { in.rr_depth = 100001; }),
       "scene.json: /integrator/rr_depth: must be in [1, 100000], got 100001"},
      {"dielectric_splits", R"({"integrator": {"dielectric_splits": 5}})",
       integrator([](auto& in) { in.dielectric_splits = 5; }),
       "scene.json: /integrator/dielectric_splits: must be in [0, 4], got 5"},
      {"ao_distance", R"({"integrator": {"ao_distance": -1}})",
       integrator([](auto& in) { in.ao_distance = -1; }),
       "scene.json: /integrator/ao_distance: must be >= 0, got -1"},
      {"albedo", R"({"materials": {"m": {"type": "diffuse", "albedo": [0.5, -0.1, 0]}}})",
       mat(MaterialType::Diffuse,
           [](auto& m) {
             m.albedo = {0.5, -0.1, 0};
           }),
       "scene.json: /materials/m/albedo/1: must be >= 0, got -0.1"},
      {"emission", R"({"materials": {"m": {"type": "mirror", "emission": [0, 0, -4]}}})",
       mat(MaterialType::Mirror,
           [](auto& m) {
             m.emission = {0, 0, -4};
           }),
       "scene.json: /materials/m/emission/2: must be >= 0, got -4"},
      {"reflectance", R"({"materials": {"m": {"type": "mirror", "reflectance": [-1, 0, 0]}}})",
       mat(MaterialType::Mirror,
           [](auto& m) {
             m.specular = {-1, 0, 0};
           }),
       "scene.json: /materials/m/reflectance/0: must be >= 0, got -1"},
      {"ior", R"({"materials": {"glass": {"type": "dielectric", "ior": -1}}})",
       [](SceneBuilder& b) {
         lucent::Material m = material("glass", MaterialType::Dielectric);
         m.ior = -1;
         b.add_material(m);
       },
       "scene.json: /materials/glass/ior: must be in [0.05, 20], got -1"},
      {"tint", R"({"materials": {"m": {"type": "dielectric", "tint": [1, -2, 1]}}})",
       mat(MaterialType::Dielectric,
           [](auto& m) {
             m.specular = {1, -2, 1};
           }),
       "scene.json: /materials/m/tint/1: must be >= 0, got -2"},
      {"roughness", R"({"materials": {"m": {"type": "conductor", "roughness": 1.5}}})",
       mat(MaterialType::Conductor, [](auto& m) { m.roughness = 1.5; }),
       "scene.json: /materials/m/roughness: must be in [0, 1], got 1.5"},
      {"conductor specular",
       R"({"materials": {"m": {"type": "conductor", "specular": [1, 1, -1]}}})",
       mat(MaterialType::Conductor,
           [](auto& m) {
             m.specular = {1, 1, -1};
           }),
       "scene.json: /materials/m/specular/2: must be >= 0, got -1"},
      {"plastic ior", R"({"materials": {"m": {"type": "plastic", "ior": 0}}})",
       mat(MaterialType::Plastic, [](auto& m) { m.ior = 0; }),
       "scene.json: /materials/m/ior: must be in [0.05, 20], got 0"},
      // above ~1.8e19 the kernel's float squares overflowed: glass of ior 1e20 rendered black
      {"rough glass ior", R"({"materials": {"m": {"type": "rough_dielectric", "ior": 1e20}}})",
       mat(MaterialType::RoughDielectric, [](auto& m) { m.ior = 1e20; }),
       "scene.json: /materials/m/ior: must be in [0.05, 20], got 1e+20"},
      {"plastic roughness", R"({"materials": {"m": {"type": "plastic", "roughness": -0.5}}})",
       mat(MaterialType::Plastic, [](auto& m) { m.roughness = -0.5; }),
       "scene.json: /materials/m/roughness: must be in [0, 1], got -0.5"},
      // diffuse_mirror: components in [0, 1], and no channel reflects more than it receives
      {"diffuse_mirror albedo",
       R"({"materials": {"m": {"type": "diffuse_mirror", "albedo": [0.5, 0.5, 1.2], "reflectance": [0, 0, 0]}}})",
       mat(MaterialType::DiffuseMirror,
           [](auto& m) {
             m.albedo = {0.5, 0.5, 1.2};
             m.specular = {0, 0, 0};
           }),
       "scene.json: /materials/m/albedo/2: must be in [0, 1], got 1.2"},
      {"diffuse_mirror reflectance",
       R"({"materials": {"m": {"type": "diffuse_mirror", "albedo": [0, 0, 0], "reflectance": [0.5, -0.5, 0]}}})",
       mat(MaterialType::DiffuseMirror,
           [](auto& m) {
             m.albedo = {0, 0, 0};
             m.specular = {0.5, -0.5, 0};
           }),
       "scene.json: /materials/m/reflectance/1: must be >= 0, got -0.5"},
      {"diffuse_mirror energy",
       R"({"materials": {"m": {"type": "diffuse_mirror", "albedo": [0.7, 0.5, 0.3], "reflectance": [0.3, 0.6, 0.3]}}})",
       mat(MaterialType::DiffuseMirror,
           [](auto& m) {
             m.albedo = {0.7, 0.5, 0.3};
             m.specular = {0.3, 0.6, 0.3};
           }),
       "scene.json: /materials/m/reflectance/1: albedo + reflectance must be <= 1 in each "
       "channel (the surface would reflect more light than it receives), got 0.5 + 0.6 = 1.1 in "
       "green"},
      {"diffuse_mirror default reflectance",
       R"({"materials": {"m": {"type": "diffuse_mirror", "albedo": [0.9, 0.8, 0.8]}}})",
       mat(MaterialType::DiffuseMirror,
           [](auto& m) {
             m.albedo = {0.9, 0.8, 0.8};
             m.specular = {0.2, 0.2, 0.2};
           }),
       "scene.json: /materials/m/reflectance/0: albedo + reflectance must be <= 1 in each "
       "channel (the surface would reflect more light than it receives), got 0.9 + 0.2 = 1.1 in "
       "red"},
      {"empty name", R"({"materials": {"": {"type": "diffuse"}}})",
       [](SceneBuilder& b) { b.add_material(material("", MaterialType::Diffuse)); },
       "scene.json: /materials/: material names must not be empty"},
      {"radius of the fourth shape", std::string("{") + kM + R"(, "shapes": [
           {"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"},
           {"type": "triangles", "material": "m", "positions": [[0,0,0],[1,0,0],[0,1,0]],
            "indices": [0, 1, 2]},
           {"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"},
           {"type": "sphere", "center": [0, 0, 0], "radius": -1, "material": "m"}]})",
       [](SceneBuilder& b) {
         add_m(b);
         b.add_sphere({{0, 0, 0}, 1, "m"});
         b.add_mesh(triangle());
         b.add_sphere({{0, 0, 0}, 1, "m"});
         b.add_sphere({{0, 0, 0}, -1, "m"});
       },
       "scene.json: /shapes/3/radius: must be > 0, got -1"},
      {"sphere material",
       std::string("{") + kM +
           R"(, "shapes": [{"type": "sphere", "center": [0,0,0], "radius": 1, "material": "gold"}]})",
       [](SceneBuilder& b) {
         add_m(b);
         b.add_sphere({{0, 0, 0}, 1, "gold"});
       },
       "scene.json: /shapes/0/material: unknown material 'gold'"},
      {"mesh material",
       std::string("{") + kM + R"(, "shapes": [{"type": "triangles", "material": "Gold", )" +
           tri_pos + R"("indices": [0, 1, 2]}]})",
       [](SceneBuilder& b) {
         add_m(b);
         b.add_mesh(triangle("Gold"));
       },
       "scene.json: /shapes/0/material: unknown material 'Gold'"},
      {"obj material",
       std::string("{") + kM +
           R"(, "shapes": [{"type": "mesh", "file": "x.obj", "material": "wood"}]})",
       [](SceneBuilder& b) {
         add_m(b);
         lucent::ObjShape obj;
         obj.file = "x.obj";
         obj.material = "wood";
         b.add_obj(obj);
       },
       "scene.json: /shapes/0/material: unknown material 'wood'"},
      {"index", tri_json(tri_pos + R"("indices": [0, 1, 3])"), mesh([](auto& t) {
         t.indices = {0, 1, 3};
       }),
       "scene.json: /shapes/0/indices/2: must be in [0, 2], got 3"},
      {"index count", tri_json(tri_pos + R"("indices": [0, 1])"), mesh([](auto& t) {
         t.indices = {0, 1};
       }),
       "scene.json: /shapes/0/indices: must be a non-empty array whose length is a multiple of 3"},
      {"no positions", tri_json(R"("positions": [], "indices": [])"), mesh([](auto& t) {
         t.positions.clear();
         t.indices.clear();
       }),
       "scene.json: /shapes/0/positions: must be a non-empty array of [x, y, z]"},
      {"normals", tri_json(tri_pos + R"("indices": [0, 1, 2], "normals": [[0,0,1],[0,0,1]])"),
       mesh([](auto& t) {
         t.normals = {{0, 0, 1}, {0, 0, 1}};
       }),
       "scene.json: /shapes/0/normals: must have one entry per position (3), got 2"},
      {"uvs", tri_json(tri_pos + R"("indices": [0, 1, 2], "uvs": [[0, 0]])"), mesh([](auto& t) {
         t.uvs = {{0, 0}};
       }),
       "scene.json: /shapes/0/uvs: must have one entry per position (3), got 1"},
      {"intensity",
       R"({"lights": [{"type": "point", "position": [0,0,0], "intensity": [1,-1,1]}]})",
       [](SceneBuilder& b) {
         b.add_light(lucent::point_light({0, 0, 0}, {1, -1, 1}));
       },
       "scene.json: /lights/0/intensity/1: must be >= 0, got -1"},
      {"radiance", R"({"lights": [{"type": "environment", "radiance": [-1, 0, 0]}]})",
       [](SceneBuilder& b) {
         b.add_light(lucent::environment_light({-1, 0, 0}));
       },
       "scene.json: /lights/0/radiance/0: must be >= 0, got -1"},
      {"two environments",
       R"({"lights": [{"type": "environment", "radiance": [1, 1, 1]},
                      {"type": "point", "position": [0,0,0], "intensity": [1,1,1]},
                      {"type": "environment", "radiance": [1, 1, 1]}]})",
       [](SceneBuilder& b) {
         b.add_light(lucent::environment_light({1, 1, 1}));
         b.add_light(lucent::point_light({0, 0, 0}, {1, 1, 1}));
         b.add_light(lucent::environment_light({1, 1, 1}));
       },
       "scene.json: /lights/2: only one environment light is allowed"},
      {"sphere light", R"({"lights": [{"type": "sphere"}]})",
       [](SceneBuilder& b) {
         lucent::Light l;
         l.type = lucent::LightType::Sphere;
         b.add_light(l);
       },
       "scene.json: /lights/0/type: 'sphere' lights are emissive shapes, not entries of "
       "\"lights\": give a shape a material with \"emission\""},
  };
}

// Every value check, through both paths: the same message, naming the same place.
TEST(SceneBuilder, SameErrorsAsJson) {
  for (const Case& c : cases()) {
    EXPECT_EQ(json_error(c.json), c.message) << c.what << ": JSON " << c.json;
    EXPECT_EQ(code_error(c.code), c.message) << c.what << ": code";
  }
}

// The same cases, each fixed, load and build without error: the cases test the value they name.
TEST(SceneBuilder, ValidNeighboursOfTheCasesAreAccepted) {
  EXPECT_EQ(code_error([](SceneBuilder& b) {
              lucent::Camera c;
              c.fov_degrees = 179;
              c.focus_distance = 0;  // the distance to look_at
              b.set_camera(c);
              lucent::Film f;
              f.width = f.height = lucent::limits::kMaxImageSize;
              f.filter.radius = lucent::limits::kMaxFilterRadius;
              b.set_film(f);
              lucent::Integrator in;
              in.spp = lucent::limits::kMaxSpp;
              in.max_depth = in.rr_depth = lucent::limits::kMaxDepth;
              b.set_integrator(in);
              lucent::Material m = material("m", lucent::MaterialType::Conductor);
              m.roughness = 1;
              b.add_material(m);
              b.add_mesh(triangle());
              b.add_light(lucent::environment_light({0, 0, 0}));
            }),
            "");
  EXPECT_EQ(json_error(R"({"camera": {"focus_distance": 0}, "integrator": {"ao_distance": 0}})"),
            "");
}

// Values only code can give (JSON has no NaN, no texture index, no raw matrix): still one line
// naming the place.
TEST(SceneBuilder, CodeOnlyErrors) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(code_error([&](SceneBuilder& b) {
              add_m(b);
              b.add_sphere({{0, nan, 0}, 1, "m"});
            }),
            "scene.json: /shapes/0/center/1: must be a finite number, got nan");
  EXPECT_EQ(code_error([&](SceneBuilder& b) {
              lucent::Camera c;
              c.fov_degrees = nan;
              b.set_camera(c);
            }),
            "scene.json: /camera/fov: must be a finite number, got nan");
  EXPECT_EQ(code_error([](SceneBuilder& b) {
              add_m(b);
              lucent::MeshShape t = triangle();
              t.positions[1].z = INFINITY;
              b.add_mesh(t);
            }),
            "scene.json: /shapes/0/positions/1/2: must be a finite number, got inf");
  EXPECT_EQ(code_error([](SceneBuilder& b) {
              add_m(b);
              lucent::MeshShape t = triangle();
              t.transform[0][0] = 0;  // a zero scale along x
              b.add_mesh(t);
            }),
            "scene.json: /shapes/0/transform: must be invertible");
  EXPECT_EQ(code_error([](SceneBuilder& b) {
              add_m(b);
              lucent::MeshShape t = triangle();
              t.transform[2][3] = 1;  // row 3, column 2: a projective matrix
              b.add_mesh(t);
            }),
            "scene.json: /shapes/0/transform: the last row must be [0, 0, 0, 1] (affine "
            "transforms only)");
  EXPECT_EQ(code_error([](SceneBuilder& b) {
              lucent::Material m = material("m", lucent::MaterialType::Diffuse);
              m.albedo_texture = 0;
              b.add_material(m);
            }),
            "scene.json: /materials/m/albedo/texture: must be the index of a texture of the "
            "scene (0), or -1, got 0");
  EXPECT_EQ(code_error([](SceneBuilder& b) { b.add_light(lucent::environment_map(3)); }),
            "scene.json: /lights/0/texture: must be the index of a texture of the scene (0), "
            "got 3");
  EXPECT_EQ(code_error([](SceneBuilder& b) {
              b.add_texture(lucent::texture_from_rgba(1, 1, {1, 1, 1, 1}));
              b.add_light(lucent::environment_map(0, -2));
            }),
            "scene.json: /lights/0/scale: must be >= 0, got -2");
  EXPECT_EQ(code_error([](SceneBuilder& b) {
              add_m(b);
              add_m(b);
            }),
            "scene.json: /materials/m: there is already a material named 'm'");
  EXPECT_EQ(code_error([](SceneBuilder& b) {
              lucent::Integrator in;
              in.type = static_cast<lucent::IntegratorType>(99);
              b.set_integrator(in);
            }),
            "scene.json: /integrator/type: unknown integrator 99 (expected one of: " +
                lucent::type_names<lucent::IntegratorType>() + ")");
  // diffuse_mirror with a textured albedo: its brightest texel in each channel plus the
  // reflectance must not exceed 1 (the colour, which the texture replaces, is not checked)
  auto textured = [](float texel_green, double reflectance) {
    return code_error([=](SceneBuilder& b) {
      b.add_texture(
          lucent::texture_from_rgba(2, 1, {0.1f, 0.2f, 0.3f, 1, 0.4f, texel_green, 0, 1}));
      lucent::Material m = material("m", lucent::MaterialType::DiffuseMirror);
      m.albedo = {5, 5, 5};
      m.albedo_texture = 0;
      m.specular = glm::dvec3(reflectance);
      b.add_material(m);
    });
  };
  EXPECT_EQ(textured(0.5f, 0.5), "");
  EXPECT_EQ(textured(0.75f, 0.5),
            "scene.json: /materials/m/reflectance/1: albedo + reflectance must be <= 1 in each "
            "channel (the surface would reflect more light than it receives), got 0.75 (the "
            "albedo texture's brightest texel) + 0.5 = 1.25 in green");
  // a scene without a name: the messages start with the place
  EXPECT_EQ(error_of([] {
              SceneBuilder().add_sphere({{0, 0, 0}, 1, "m"});
            }),
            "/shapes/0/material: unknown material 'm'");
}

// A Scene's fields are public (and Python's attributes write them): the renderer and the
// reference check the whole scene before packing it, with the builder's messages and places. A
// NaN camera position crashed the kernel's traversal before; an index out of range read past
// the scene's arrays when packing.
// A transform's scale does not decide whether it is invertible, nor which way its normals and
// front sides face: a uniform scale of 1e-110 (determinant 1e-330, which underflows) was refused
// as "not invertible", and one of -1e-110 would have kept the unmirrored winding.
TEST(SceneBuilder, TransformsOfAnyScaleKeepNormalsAndWinding) {
  for (const double s : {1e-110, -1e-110, 1e11, -1e11, 1.0, -1.0}) {
    SCOPED_TRACE(s);
    SceneBuilder b("scene.json");
    add_m(b);
    lucent::MeshShape t = triangle();
    t.normals.assign(3, {0, 0, 1});
    t.transform = glm::dmat4(s);
    t.transform[3][3] = 1;
    b.add_mesh(t);
    const lucent::Scene scene = b.build();
    ASSERT_EQ(scene.normals.size(), 3u);
    EXPECT_EQ(scene.normals[0], glm::dvec3(0, 0, s > 0 ? 1 : -1));  // exactly: a diagonal
    ASSERT_EQ(scene.triangles.size(), 1u);
    EXPECT_EQ(scene.triangles[0].v[1], s > 0 ? 1 : 2);  // mirrored: the winding is reversed
  }
  // scales of 1e-200 along x and y (determinant 1e-400): a normal (1, 1, 1) leans to (1, 1, 0)
  SceneBuilder b("scene.json");
  add_m(b);
  lucent::MeshShape t = triangle();
  t.normals.assign(3, {1, 1, 1});
  t.transform = glm::scale(glm::dmat4(1.0), glm::dvec3(1e-200, 1e-200, 1));
  b.add_mesh(t);
  const lucent::Scene scene = b.build();
  ASSERT_EQ(scene.normals.size(), 3u);
  EXPECT_LT(glm::length(scene.normals[0] - glm::dvec3(1, 1, 0) / std::sqrt(2.0)), 1e-15);
}

TEST(SceneBuilder, ScenesEditedDirectlyAreCheckedBeforeRendering) {
  SceneBuilder b("scene.json");
  add_m(b);
  b.add_sphere({{0, 0, -3}, 1, "m"});
  lucent::MeshShape two = triangle();
  two.positions.push_back({1, 1, 0});
  two.indices = {0, 1, 2, 2, 1, 3};
  b.add_mesh(two);
  b.add_texture(lucent::texture_from_rgba(1, 1, {1, 1, 1, 1}));
  lucent::Film film;
  film.width = 8;
  film.height = 6;
  b.set_film(film);
  const lucent::Scene good = b.build();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Edit {
    std::function<void(lucent::Scene&)> edit;
    std::string message;
  } edits[] = {
      {[&](lucent::Scene& s) { s.camera.position.x = nan; },
       "/camera/position/0: must be a finite number, got nan"},
      {[](lucent::Scene& s) { s.film.width = -3; }, "/film/width: must be >= 1, got -3"},
      {[](lucent::Scene& s) { s.film.filter.radius = 0; },
       "/film/filter/radius: must be > 0, got 0"},
      {[](lucent::Scene& s) { s.integrator.max_depth = 0; },
       "/integrator/max_depth: must be in [1, 100000], got 0"},
      {[](lucent::Scene& s) { s.integrator.dielectric_splits = -1; },
       "/integrator/dielectric_splits: must be in [0, 4], got -1"},
      {[](lucent::Scene& s) { s.spheres[0].material = 1; },
       "/shapes/0/material: must index one of the scene's 1 materials, got 1"},
      // as the loader says: a negative radius rendered the sphere inside out
      {[](lucent::Scene& s) { s.spheres[0].radius = -0.5; },
       "/shapes/0/radius: must be > 0, got -0.5"},
      {[](lucent::Scene& s) { s.spheres[0].radius = 0; }, "/shapes/0/radius: must be > 0, got 0"},
      {[](lucent::Scene& s) { s.triangles[1].v[2] = 4; },
       "/shapes/1 (triangle 1)/v/2: must index one of the scene's 4 positions, got 4"},
      {[](lucent::Scene& s) {
         s.triangles[0].uv[0] = s.triangles[0].uv[1] = s.triangles[0].uv[2] = 0;
       },
       "/shapes/1 (triangle 0)/uv/0: must index one of the scene's 0 uvs, got 0"},
      {[](lucent::Scene& s) { s.textures[0].rgba.pop_back(); },
       "/textures/0/rgba: must hold 4 x 1 x 1 = 4 floats, got 3"},
      {[](lucent::Scene& s) {
         s.materials[0].albedo = {0.5, -1, 0.5};
       },
       "/materials/m/albedo/1: must be >= 0, got -1"},
      {[](lucent::Scene& s) {
         s.materials[0].name = "";
         s.materials[0].ior = 0;
         s.materials[0].type = lucent::MaterialType::Dielectric;
       },
       "/materials/0/ior: must be in [0.05, 20], got 0"},
      {[](lucent::Scene& s) { s.materials[0].albedo_texture = 2; },
       "/materials/m/albedo/texture: must be the index of a texture of the scene (1), or -1, got "
       "2"},
      {[](lucent::Scene& s) { s.lights.push_back(lucent::environment_map(5)); },
       "/lights/0/texture: must be the index of a texture of the scene (1), got 5"},
  };
  for (const Edit& e : edits) {
    lucent::Scene s = good;
    e.edit(s);
    lucent::Renderer r(lucent::test::session_options());
    EXPECT_EQ(error_of([&] { r.set_scene(s); }), "scene.json: " + e.message);
    EXPECT_EQ(error_of([&] { lucent::render_reference(s, lucent::ReferenceOptions{}); }),
              "scene.json: " + e.message);
  }
  // primitives outside the shape list are named by their list
  lucent::Scene s = good;
  s.shapes.clear();
  s.triangles[1].material = -1;
  EXPECT_EQ(error_of([&] { lucent::render_reference(s, lucent::ReferenceOptions{}); }),
            "scene.json: /triangles/1/material: must index one of the scene's 1 materials, got -1");
  // and the unedited scene renders (the full kernel, which many tests share: a specialised one
  // cost CI a cold kernel build)
  lucent::Renderer r(lucent::test::session_options());
  r.set_build_options(lucent::Precision::Float, false, false);
  r.set_scene(good);
  r.render(1);
  EXPECT_EQ(r.spp(), 1u);
}

TEST(SceneBuilder, TexturesFromMemory) {
  // linear floats are kept as they are; the size and the values are checked when added
  lucent::Texture t = lucent::texture_from_rgba(2, 1, {0.5f, 1, 2, 1, 0, 0.25f, 0, 0.5f}, "t");
  EXPECT_EQ(t.path, "t");
  SceneBuilder b("s");
  EXPECT_EQ(b.add_texture(t), 0);
  EXPECT_EQ(b.scene().textures[0].rgba, t.rgba);
  EXPECT_EQ(error_of([&] {
              b.add_texture(lucent::texture_from_rgba(2, 2, {1, 1, 1, 1}));
            }),
            "s: /textures/1/rgba: must hold 4 x 2 x 2 = 16 floats, got 4");
  EXPECT_EQ(error_of([&] {
              b.add_texture(lucent::texture_from_rgba(1, 1, {1, -1, 1, 1}));
            }),
            "s: /textures/1/rgba/1: must be >= 0, got -1");
  EXPECT_EQ(error_of([&] { b.add_texture(lucent::texture_from_rgba(0, 1, {})); }),
            "s: /textures/1/width: must be >= 1, got 0");
  EXPECT_EQ(b.scene().textures.size(), 1u);  // the failed calls added nothing

  // 8-bit sRGB data decodes as the same bytes in a PNG file do, for 1 to 4 channels
  std::string dir = lucent::test::temp_dir();
  const int w = 3, h = 2;
  for (int channels = 1; channels <= 4; ++channels) {
    std::vector<std::uint8_t> data(w * h * channels);
    for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<std::uint8_t>(i * 41 + 7);
    std::string png = dir + "/t" + std::to_string(channels) + ".png";
    ASSERT_NE(stbi_write_png(png.c_str(), w, h, channels, data.data(), w * channels), 0);
    SceneBuilder files("f");
    const lucent::Texture& from_file = files.scene().textures.at(files.load_texture(png));
    lucent::Texture from_memory = lucent::texture_from_srgb8(w, h, channels, data);
    EXPECT_EQ(from_memory.width, w);
    EXPECT_EQ(from_memory.height, h);
    EXPECT_EQ(from_memory.rgba, from_file.rgba) << channels << " channels";
  }
  // the sRGB curve itself: 0 -> 0, 255 -> 1, 188 -> about 0.5
  lucent::Texture grey = lucent::texture_from_srgb8(3, 1, 1, {0, 188, 255});
  EXPECT_EQ(grey.rgba[0], 0.0f);
  EXPECT_NEAR(grey.rgba[4], 0.5029, 1e-4);
  EXPECT_EQ(grey.rgba[8], 1.0f);
  EXPECT_EQ(grey.rgba[11], 1.0f);  // no alpha channel: opaque
  EXPECT_EQ(error_of([] {
              lucent::texture_from_srgb8(2, 2, 3, {1, 2, 3});
            }),
            "texture_from_srgb8: 2x2 texels of 3 bytes need 12 bytes, got 3");
  EXPECT_EQ(error_of([] {
              lucent::texture_from_srgb8(1, 1, 5, {1, 2, 3, 4, 5});
            }),
            "texture_from_srgb8: channels must be 1 to 4, got 5");
  // (it said "need 0 bytes, got 12")
  EXPECT_EQ(
      error_of([] { lucent::texture_from_srgb8(-2, -2, 3, std::vector<std::uint8_t>(12, 0)); }),
      "texture_from_srgb8: the size must be positive, got -2x-2");
}

// A scene built in code is the scene its JSON twin loads to: same camera, materials, geometry
// (transformed, mirrored), lights, shape entries; and the same image.
// load_texture shares a file among the materials and meshes that name it, by the files the builder
// loaded: a texture added from memory whose name is the file's path is not that file (it stood in
// for it: the file's materials rendered the texture made in code), and an OBJ's map_Kd shares the
// file a material of the builder loaded under another spelling.
TEST(SceneBuilder, TexturesFromFilesAreSharedByFileNotByName) {
  std::string dir = lucent::test::temp_dir();
  const unsigned char px[] = {255, 0, 0};
  const std::string png = dir + "/red.png";
  ASSERT_NE(stbi_write_png(png.c_str(), 1, 1, 3, px, 3), 0);
  SceneBuilder b("s");
  // a tinted copy made in code, named after the file it came from
  const int tinted = b.add_texture(lucent::texture_from_rgba(1, 1, {0, 0, 1, 1}, png));
  const int file = b.load_texture(png);
  EXPECT_NE(file, tinted);
  ASSERT_EQ(b.scene().textures.size(), 2u);
  EXPECT_EQ(b.scene().textures[file].rgba, (std::vector<float>{1, 0, 0, 1}));
  EXPECT_EQ(b.load_texture(dir + "/./red.png"), file);  // the same file, spelled otherwise
  lucent::test::write_file(dir + "/m.mtl", "newmtl a\nKd 0.5 0.5 0.5\nmap_Kd red.png\n");
  lucent::test::write_file(dir + "/m.obj",
                           "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n");
  lucent::ObjShape obj;
  obj.file = dir + "/m.obj";
  b.add_obj(obj);
  EXPECT_EQ(b.scene().textures.size(), 2u);
  EXPECT_EQ(b.scene().materials.back().albedo_texture, file);
}

// The builder finds materials by name through an index (a search of the list for each made a
// scene of N materials load in N^2 / 2 comparisons: 200,000 took 99.6 s, now 1.5 s), which must
// say what the list says: the materials an OBJ's MTL made are known to later shapes and refuse a
// later material of their name; those of an OBJ that failed to load are not; the first of two
// equal names made unique by the MTL loader keeps its own.
TEST(SceneBuilder, MaterialNamesFollowTheList) {
  const std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/m.mtl", "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n");
  lucent::test::write_file(dir + "/m.obj",
                           "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n");
  lucent::test::write_file(dir + "/bad.obj",
                           "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl blue\nf 1 2 3\n"
                           "f 1 2 9\n");
  SceneBuilder b("s.json");
  add_m(b);
  lucent::ObjShape obj;
  obj.file = dir + "/m.obj";
  b.add_obj(obj);
  ASSERT_EQ(b.scene().materials.size(), 2u);
  EXPECT_EQ(b.scene().materials[1].name, "m.obj:red");
  // a later shape names it; a later material cannot take its name
  b.add_sphere({{0, 0, 0}, 1, "m.obj:red"});
  EXPECT_EQ(b.scene().spheres.back().material, 1);
  EXPECT_EQ(error_of([&] { b.add_material(material("m.obj:red", lucent::MaterialType::Diffuse)); }),
            "s.json: /materials/m.obj:red: there is already a material named 'm.obj:red'");
  // an OBJ that fails leaves no material, and no name
  obj.file = dir + "/bad.obj";
  EXPECT_NE(error_of([&] { b.add_obj(obj); }), "");
  EXPECT_EQ(b.scene().materials.size(), 2u);
  EXPECT_EQ(error_of([&] {
              b.add_sphere({{0, 0, 0}, 1, "bad.obj:blue"});
            }),
            "s.json: /shapes/2/material: unknown material 'bad.obj:blue'");
  EXPECT_EQ(b.add_material(material("bad.obj:blue", lucent::MaterialType::Diffuse)), 2);
  // the same OBJ again shares its material; another file's material of that name is made
  // unique beside the one a material of the builder holds
  obj.file = dir + "/m.obj";
  b.add_obj(obj);
  EXPECT_EQ(b.scene().materials.size(), 3u);
  std::filesystem::create_directories(dir + "/sub");
  lucent::test::write_file(dir + "/sub/bad.obj",
                           "mtllib ../m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl blue\nf 1 2 3\n");
  obj.file = dir + "/sub/bad.obj";
  b.add_obj(obj);
  ASSERT_EQ(b.scene().materials.size(), 4u);
  EXPECT_EQ(b.scene().materials[3].name, "sub/bad.obj:blue");
  b.add_sphere({{0, 0, 0}, 1, "bad.obj:blue"});
  b.add_sphere({{0, 0, 0}, 1, "sub/bad.obj:blue"});
  EXPECT_EQ(b.scene().spheres[b.scene().spheres.size() - 2].material, 2);
  EXPECT_EQ(b.scene().spheres.back().material, 3);
  // and build() starts the next scene with none
  b.build();
  EXPECT_EQ(error_of([&] {
              b.add_sphere({{0, 0, 0}, 1, "m"});
            }),
            "s.json: /shapes/0/material: unknown material 'm'");
}

TEST(SceneBuilder, EqualsTheSameSceneFromJson) {
  lucent::Scene from_json = lucent::parse_scene(R"({
    "camera": {"position": [0, 0.5, 4], "look_at": [0, 0.3, 0], "fov": 35, "aperture": 0.01},
    "film": {"width": 12, "height": 10, "filter": {"type": "tent"}},
    "integrator": {"type": "path", "max_depth": 4, "spp": 2, "seed": 3},
    "materials": {
      "wall": {"type": "diffuse", "albedo": [0.25, 0.5, 0.75]},
      "lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [4, 3, 2]},
      "gold": {"type": "conductor", "specular": [1, 0.78, 0.34], "roughness": 0.2}
    },
    "shapes": [
      {"type": "sphere", "center": [0.3, 0.2, 0], "radius": 0.4, "material": "gold"},
      {"type": "triangles", "material": "wall",
       "positions": [[-2, 0, -2], [2, 0, -2], [2, 0, 2], [-2, 0, 2]], "indices": [0, 2, 1, 0, 3, 2],
       "normals": [[0, 1, 0], [0, 1, 0], [0, 1, 0], [0, 1, 0]],
       "uvs": [[0, 0], [1, 0], [1, 1], [0, 1]]},
      {"type": "triangles", "material": "lamp",
       "positions": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "indices": [0, 1, 2],
       "transform": [{"scale": [-1, 1, 1]}, {"translate": [0, 1.5, 0]}]}
    ],
    "lights": [
      {"type": "point", "position": [0, 3, 2], "intensity": [5, 5, 5]},
      {"type": "environment", "radiance": [0.1, 0.2, 0.3]}
    ]
  })",
                                                "twin");

  SceneBuilder b("twin");
  lucent::Camera c;
  c.position = {0, 0.5, 4};
  c.look_at = {0, 0.3, 0};
  c.fov_degrees = 35;
  c.aperture = 0.01;
  b.set_camera(c);
  lucent::Film f;
  f.width = 12;
  f.height = 10;
  f.filter = {lucent::FilterType::Tent, lucent::default_filter_radius(lucent::FilterType::Tent)};
  b.set_film(f);
  lucent::Integrator in;
  in.max_depth = 4;
  in.spp = 2;
  in.seed = 3;
  b.set_integrator(in);
  lucent::Material wall = material("wall", lucent::MaterialType::Diffuse);
  wall.albedo = {0.25, 0.5, 0.75};
  lucent::Material lamp = material("lamp", lucent::MaterialType::Diffuse);
  lamp.albedo = {0, 0, 0};
  lamp.emission = {4, 3, 2};
  lucent::Material gold = material("gold", lucent::MaterialType::Conductor);
  gold.specular = {1, 0.78, 0.34};
  gold.roughness = 0.2;
  for (const lucent::Material& m : {gold, lamp, wall}) b.add_material(m);  // JSON: by name
  b.add_sphere({{0.3, 0.2, 0}, 0.4, "gold"});
  lucent::MeshShape floor;
  floor.positions = {{-2, 0, -2}, {2, 0, -2}, {2, 0, 2}, {-2, 0, 2}};
  floor.indices = {0, 2, 1, 0, 3, 2};
  floor.normals.assign(4, {0, 1, 0});
  floor.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  floor.material = "wall";
  b.add_mesh(floor);
  lucent::MeshShape light = triangle("lamp");
  light.transform = glm::dmat4(1.0);
  light.transform[0][0] = -1;   // scale x by -1 (mirroring) ...
  light.transform[3][1] = 1.5;  // ... then translate y by 1.5
  b.add_mesh(light);
  b.add_light(lucent::point_light({0, 3, 2}, {5, 5, 5}));
  b.add_light(lucent::environment_light({0.1, 0.2, 0.3}));
  lucent::Scene from_code = b.build();

  EXPECT_EQ(from_code.path, from_json.path);
  EXPECT_EQ(from_code.camera.position, from_json.camera.position);
  EXPECT_EQ(from_code.camera.focus_distance, from_json.camera.focus_distance);
  EXPECT_EQ(from_code.film.filter.radius, from_json.film.filter.radius);
  EXPECT_EQ(from_code.integrator.seed, from_json.integrator.seed);
  ASSERT_EQ(from_code.materials.size(), from_json.materials.size());
  for (std::size_t i = 0; i < from_code.materials.size(); ++i) {
    EXPECT_EQ(from_code.materials[i].name, from_json.materials[i].name);
    EXPECT_EQ(from_code.materials[i].albedo, from_json.materials[i].albedo);
    EXPECT_EQ(from_code.materials[i].specular, from_json.materials[i].specular);
  }
  EXPECT_EQ(from_code.positions, from_json.positions);
  EXPECT_EQ(from_code.normals, from_json.normals);
  EXPECT_EQ(from_code.uvs, from_json.uvs);
  ASSERT_EQ(from_code.triangles.size(), from_json.triangles.size());
  for (std::size_t i = 0; i < from_code.triangles.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(from_code.triangles[i].v[k], from_json.triangles[i].v[k]);
      EXPECT_EQ(from_code.triangles[i].n[k], from_json.triangles[i].n[k]);
      EXPECT_EQ(from_code.triangles[i].uv[k], from_json.triangles[i].uv[k]);
    }
  ASSERT_EQ(from_code.shapes.size(), 3u);
  ASSERT_EQ(from_json.shapes.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(from_code.shapes[i].type, from_json.shapes[i].type);
    EXPECT_EQ(from_code.shapes[i].first, from_json.shapes[i].first);
    EXPECT_EQ(from_code.shapes[i].count, from_json.shapes[i].count);
  }
  EXPECT_EQ(from_json.shapes[1].type, lucent::ShapeType::Triangle);
  EXPECT_EQ(from_json.shapes[1].count, 2u);
  ASSERT_EQ(from_code.lights.size(), 2u);
  EXPECT_EQ(from_code.lights[1].radiance, from_json.lights[1].radiance);

  // the mirrored lamp keeps its front side towards +z (the side its emission leaves from)
  const lucent::Triangle& t = from_code.triangles[2];
  glm::dvec3 a = from_code.positions[t.v[0]], bb = from_code.positions[t.v[1]],
             cc = from_code.positions[t.v[2]];
  EXPECT_GT(glm::cross(bb - a, cc - a).z, 0);

  // 2 spp are two passes of one sample: the images are equal to the last bit
  lucent::RenderOptions o;
  lucent::RenderResult rj = lucent::render(from_json, o), rc = lucent::render(from_code, o);
  EXPECT_EQ(rc.mean.rgb, rj.mean.rgb);
  double sum = 0;
  for (float v : rc.mean.rgb) sum += v;
  EXPECT_GT(sum, 0);
}

}  // namespace

}  // namespace test_scene_builder
