// Feature-specialised kernels: the build options carry exactly the features the scene uses
// (a scene without glass compiles no dielectric code), --no-specialize carries all of them, and
// both kernels render the same image.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "render/features.hpp"
#include "render/pack.hpp"
#include "support.hpp"

namespace test_features {

namespace {

const char* kDiffuseScene = R"({
  "camera": {"position": [0, 1, 5], "look_at": [0, 0.5, 0], "fov": 40},
  "film": {"width": 16, "height": 12},
  "integrator": {"type": "path", "max_depth": 4},
  "materials": {"w": {"type": "diffuse", "albedo": [0.7, 0.6, 0.5]}},
  "shapes": [{"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5, "material": "w"},
             {"type": "sphere", "center": [0, -100, 0], "radius": 100, "material": "w"}],
  "lights": [{"type": "point", "position": [2, 4, 3], "intensity": [20, 20, 20]}]})";

std::vector<std::string> features_of(const std::string& json) {
  lucent::Scene s = lucent::parse_scene(json, "features.json");
  return lucent::render_detail::scene_features(s, lucent::render_detail::pack_scene(s));
}

bool has(const std::vector<std::string>& v, const std::string& f) {
  return std::find(v.begin(), v.end(), f) != v.end();
}

TEST(Features, DiffuseSpheresAndAPointLightCompileOnlyThat) {
  std::vector<std::string> f = features_of(kDiffuseScene);
  std::vector<std::string> expected = {"LC_HAS_SPHERES",         "LC_HAS_DIFFUSE",
                                       "LC_HAS_POINT_LIGHTS",    "LC_HAS_FILTER_BOX",
                                       "LC_HAS_INTEGRATOR_PATH", "LC_HAS_SAMPLER_SOBOL"};
  std::sort(f.begin(), f.end());
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(f, expected);
  // and the render really is built with those options only
  lucent::RenderResult r = lucent::test::render_json(kDiffuseScene, 1);
  EXPECT_EQ(r.build_options.find("LC_HAS_DIELECTRIC"), std::string::npos) << r.build_options;
  EXPECT_EQ(r.build_options.find("LC_HAS_TEXTURES"), std::string::npos) << r.build_options;
  EXPECT_NE(r.build_options.find("-D LC_HAS_SPHERES"), std::string::npos) << r.build_options;
}

TEST(Features, EachUsedFeatureAppears) {
  std::string glass = kDiffuseScene;
  glass.replace(
      glass.find(R"("w": {"type": "diffuse", "albedo": [0.7, 0.6, 0.5]})"),
      std::string(R"("w": {"type": "diffuse", "albedo": [0.7, 0.6, 0.5]})").size(),
      R"("w": {"type": "diffuse", "albedo": [0.7, 0.6, 0.5]}, "g": {"type": "dielectric", "ior": 1.5})");
  // a glass material that is declared but used by no shape costs nothing
  EXPECT_FALSE(has(features_of(glass), "LC_HAS_DIELECTRIC"));
  std::string used = glass;
  used.replace(used.find(R"("radius": 0.5, "material": "w")"),
               std::string(R"("radius": 0.5, "material": "w")").size(),
               R"("radius": 0.5, "material": "g")");
  std::vector<std::string> f = features_of(used);
  EXPECT_TRUE(has(f, "LC_HAS_DIELECTRIC"));
  EXPECT_FALSE(has(f, "LC_HAS_MIRROR"));

  std::string rich = R"({
    "camera": {"position": [0, 1, 5], "look_at": [0, 0.5, 0], "fov": 40, "aperture": 0.1},
    "film": {"width": 8, "height": 8, "filter": {"type": "tent"}},
    "integrator": {"type": "whitted"},
    "materials": {"m": {"type": "mirror"}, "l": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [1, 1, 1]}},
    "shapes": [{"type": "triangles", "material": "l", "positions": [[0,0,0],[1,0,0],[0,1,0]],
                "normals": [[0,0,1],[0,0,1],[0,0,1]], "indices": [0, 1, 2]},
               {"type": "sphere", "center": [0, 0, -2], "radius": 1, "material": "m"}],
    "lights": [{"type": "environment", "radiance": [0.1, 0.1, 0.1]}]})";
  f = features_of(rich);
  for (const char* want : {"LC_HAS_TRIANGLES", "LC_HAS_SPHERES", "LC_HAS_SMOOTH_NORMALS",
                           "LC_HAS_MIRROR", "LC_HAS_TRIANGLE_LIGHTS", "LC_HAS_ENV",
                           "LC_HAS_THIN_LENS", "LC_HAS_FILTER_TENT", "LC_HAS_INTEGRATOR_WHITTED"})
    EXPECT_TRUE(has(f, want)) << want;
  for (const char* not_want :
       {"LC_HAS_POINT_LIGHTS", "LC_HAS_SPHERE_LIGHTS", "LC_HAS_TEXTURES", "LC_HAS_FILTER_GAUSSIAN",
        "LC_HAS_FILTER_BOX", "LC_HAS_INTEGRATOR_PATH", "LC_HAS_DIELECTRIC"})
    EXPECT_FALSE(has(f, not_want)) << not_want;
}

// A texture mapped otherwise than by default (a wrap mode other than repeat, a uv scale or
// offset) compiles the mapping code (LC_HAS_TEXTURE_MAPPING, kernels/texture/texture.cl); a
// texture mapped by default, or a mapped material no shape uses, does not.
TEST(Features, TextureMappingOnlyWhereAUsedMaterialMapsItsTexture) {
  lucent::Scene s;
  s.textures.push_back(lucent::texture_from_rgba(1, 1, {0.5f, 0.5f, 0.5f, 1}));
  lucent::Material plain, clamped;
  plain.name = "plain";
  plain.albedo_texture = 0;
  clamped = plain;
  clamped.name = "clamped";
  clamped.albedo_wrap_v = lucent::TextureWrap::Clamp;
  s.materials = {plain, clamped};
  s.spheres.push_back({{0, 0, 0}, 1, 0});
  auto features = [&] {
    return lucent::render_detail::scene_features(s, lucent::render_detail::pack_scene(s));
  };
  EXPECT_TRUE(has(features(), "LC_HAS_TEXTURES"));
  EXPECT_FALSE(has(features(), "LC_HAS_TEXTURE_MAPPING"));
  s.spheres[0].material = 1;
  EXPECT_TRUE(has(features(), "LC_HAS_TEXTURE_MAPPING"));
  s.materials[1].albedo_wrap_v = lucent::TextureWrap::Repeat;
  s.materials[1].albedo_uv_offset = {0.5, 0};
  EXPECT_TRUE(has(features(), "LC_HAS_TEXTURE_MAPPING"));
  s.materials[1].albedo_texture = -1;  // a mapping without a texture maps nothing
  EXPECT_FALSE(has(features(), "LC_HAS_TEXTURE_MAPPING"));
}

// A mapping that reads the texels of the default one is the default: repeating, a whole offset
// (uv shifted by whole periods) is the image as given, and costs neither the mapping code nor a
// texture header of its own. A mirror's offset counts in periods of 2: offsets 2 and 0 share a
// header. Triangles read the mapping from their uvs (the host maps them): a scale or offset on a
// repeating texture that no sphere uses needs no mapping code either.
TEST(Features, MappingsEquivalentToTheDefaultCostNothing) {
  lucent::Scene s;
  s.textures.push_back(lucent::texture_from_rgba(1, 1, {0.5f, 0.5f, 0.5f, 1}));
  lucent::Material m;
  m.name = "m";
  m.albedo_texture = 0;
  m.albedo_uv_offset = {1, -3};
  s.materials = {m};
  s.spheres.push_back({{0, 0, 0}, 1, 0});
  auto packed = [&] { return lucent::render_detail::pack_scene(s); };
  auto mapping = [&] {
    return has(lucent::render_detail::scene_features(s, packed()), "LC_HAS_TEXTURE_MAPPING");
  };
  EXPECT_FALSE(mapping());
  EXPECT_EQ(packed().textures.size(), 1u);
  EXPECT_EQ(packed().materials[0].p.diffuse.albedo_tex, 0);
  s.materials[0].albedo_uv_offset = {1.5, 0};  // half a period: another image
  EXPECT_TRUE(mapping());
  EXPECT_EQ(packed().textures.size(), 2u);

  // mirror: offsets by whole periods (2) share a header
  lucent::Material a = m, b = m;
  a.name = "a";
  b.name = "b";
  a.albedo_wrap_u = b.albedo_wrap_u = lucent::TextureWrap::Mirror;
  a.albedo_uv_offset = {0, 0};
  b.albedo_uv_offset = {-4, 7};
  s.materials = {a, b};
  s.spheres.push_back({{3, 0, 0}, 1, 1});
  EXPECT_TRUE(mapping());
  EXPECT_EQ(packed().textures.size(), 2u);
  EXPECT_EQ(packed().materials[0].p.diffuse.albedo_tex, packed().materials[1].p.diffuse.albedo_tex);

  // a repeating texture scaled and offset on triangles alone: mapped on the host
  lucent::Material t = m;
  t.albedo_uv_scale = {2.5, -3};
  t.albedo_uv_offset = {0.25, 0};
  s.materials = {t};
  s.spheres.clear();
  s.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  s.uvs = {{0, 0}, {1, 0}, {0, 1}};
  lucent::Triangle tri;
  tri.v[0] = tri.uv[0] = 0;
  tri.v[1] = tri.uv[1] = 1;
  tri.v[2] = tri.uv[2] = 2;
  tri.material = 0;
  s.triangles = {tri};
  EXPECT_FALSE(mapping());
  s.materials[0].albedo_wrap_v = lucent::TextureWrap::Clamp;  // a wrap mode is the kernel's
  EXPECT_TRUE(mapping());
}

TEST(Features, FullKernelHasEveryFeatureAndRendersTheSameImage) {
  lucent::Scene s = lucent::parse_scene(kDiffuseScene, "features.json");
  lucent::RenderOptions spec, full;
  spec.spp = full.spp = 16;
  full.specialize = false;
  lucent::RenderResult a = lucent::test::render(s, spec), b = lucent::test::render(s, full);
  for (const std::string& f : lucent::render_detail::all_features())
    EXPECT_NE(b.build_options.find("-D " + f), std::string::npos) << f;
  EXPECT_LT(a.build_options.size(), b.build_options.size());
  // the same seed and the same arithmetic on the paths this scene takes: equal up to rounding
  double worst = 0;
  for (size_t i = 0; i < a.mean.rgb.size(); ++i)
    worst = std::max(
        worst, std::abs(double(a.mean.rgb[i]) - b.mean.rgb[i]) / (1e-3 + std::abs(a.mean.rgb[i])));
  EXPECT_LT(worst, 1e-4);
}

}  // namespace

namespace {

// integrator.caustics compiles the light paths only where a caustic path exists: a surface that
// scatters by a delta lobe (a mirror, smooth glass, a rough dielectric of ior 1), used by a shape.
// A device's own build options (added to the scene's for its build and its cache key): PoCL's
// CPU device keeps the integrator and the light path out of line (LC_POCL_NOINLINE,
// kernels/util/math.cl), other devices get nothing: Intel's CPU runtime miscompiles the
// out-of-line integrator (BENCHMARKS.md, "Intel's CPU OpenCL runtime").
// KernelSource.KernelsAreStrictOpenCL12ForClang compiles both branches.
TEST(Features, OnlyPoclsCpuDeviceGetsThePoclDefine) {
  lucent::DeviceInfo d;
  d.type = "CPU";
  d.platform = "Portable Computing Language";
  EXPECT_EQ(lucent::render_detail::device_defines(d), " -D LC_DEVICE_POCL_CPU");
  for (const char* type : {"GPU", "accelerator", "other"}) {
    d.type = type;  // PoCL's CUDA or remote devices
    EXPECT_EQ(lucent::render_detail::device_defines(d), "") << type;
  }
  for (const char* platform : {"Intel(R) OpenCL", "AMD Accelerated Parallel Processing", ""}) {
    d.type = "CPU";
    d.platform = platform;
    EXPECT_EQ(lucent::render_detail::device_defines(d), "") << platform;
  }
}

TEST(Features, CausticsOnlyWithADeltaSurface) {
  auto scene = [](const std::string& material) {
    std::string j = kDiffuseScene;
    auto replace = [&j](const std::string& from, const std::string& to) {
      j.replace(j.find(from), from.size(), to);
    };
    replace(R"("max_depth": 4)", R"("max_depth": 4, "caustics": true)");
    replace(R"("w": {"type": "diffuse", "albedo": [0.7, 0.6, 0.5]})",
            R"("w": {"type": "diffuse", "albedo": [0.7, 0.6, 0.5]}, "x": )" + material);
    replace(R"("radius": 0.5, "material": "w")", R"("radius": 0.5, "material": "x")");
    return j;
  };
  EXPECT_FALSE(has(features_of(scene(R"({"type": "diffuse"})")), "LC_HAS_CAUSTICS"));
  EXPECT_FALSE(
      has(features_of(scene(R"({"type": "rough_dielectric", "ior": 1.5})")), "LC_HAS_CAUSTICS"));
  EXPECT_TRUE(has(features_of(scene(R"({"type": "mirror"})")), "LC_HAS_CAUSTICS"));
  EXPECT_TRUE(has(features_of(scene(R"({"type": "dielectric", "ior": 1.5})")), "LC_HAS_CAUSTICS"));
  EXPECT_TRUE(
      has(features_of(scene(R"({"type": "rough_dielectric", "ior": 1})")), "LC_HAS_CAUSTICS"));
}

// integrator.dielectric_splits: compiled in only where a path-traced scene has a smooth dielectric
// (the one BSDF that chooses between delta lobes) and the knob is on (default 2).
TEST(Features, SplittingOnlyWithSmoothGlass) {
  auto scene = [](const std::string& material, const std::string& integrator) {
    std::string j = kDiffuseScene;
    auto replace = [&j](const std::string& from, const std::string& to) {
      j.replace(j.find(from), from.size(), to);
    };
    replace(R"("max_depth": 4)", R"("max_depth": 4)" + integrator);
    replace(R"("w": {"type": "diffuse", "albedo": [0.7, 0.6, 0.5]})",
            R"("w": {"type": "diffuse", "albedo": [0.7, 0.6, 0.5]}, "x": )" + material);
    replace(R"("radius": 0.5, "material": "w")", R"("radius": 0.5, "material": "x")");
    return j;
  };
  const std::string glass = R"({"type": "dielectric", "ior": 1.5})";
  EXPECT_TRUE(has(features_of(scene(glass, "")), "LC_HAS_SPLITTING"));
  EXPECT_FALSE(has(features_of(scene(glass, R"(, "dielectric_splits": 0)")), "LC_HAS_SPLITTING"));
  EXPECT_FALSE(has(features_of(scene(R"({"type": "mirror"})", "")), "LC_HAS_SPLITTING"));
  EXPECT_FALSE(has(features_of(scene(R"({"type": "rough_dielectric", "ior": 1.5})", "")),
                   "LC_HAS_SPLITTING"));
}

}  // namespace

}  // namespace test_features
