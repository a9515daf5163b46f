// `lucent info SCENE`: scene and BVH statistics and the kernel feature defines.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <sstream>
#include <string>

#include "render/pack.hpp"
#include "support.hpp"

namespace test_cli_info {

namespace {

using lucent::test::CommandResult;
using lucent::test::run_cli;

using lucent::test::parse_report;

long long leading_int(const std::string& s) { return std::stoll(s); }

TEST(CliInfo, SceneAndBvhStatistics) {
  std::string dir = lucent::test::temp_dir();
  // a 4x2 texture: 8 texels of 16 bytes (float RGBA) on the device
  lucent::Image tex{4, 2, std::vector<float>(4 * 2 * 3, 0.5f)};
  lucent::write_image(dir + "/tex.png", tex);
  std::string scene = dir + "/scene.json";
  lucent::test::write_file(scene, R"({
    "film": {"width": 40, "height": 30, "transfer": "gamma", "gamma": 1.8, "exposure": -1.5,
             "tonemap": "aces"},
    "integrator": {"type": "direct", "max_depth": 3, "spp": 9, "seed": 5},
    "materials": {
      "white": {"type": "diffuse", "albedo": [0.8, 0.8, 0.8]},
      "wood":  {"type": "diffuse", "albedo": {"texture": "tex.png"}},
      "lamp":  {"type": "diffuse", "emission": [5, 5, 5]},
      "chrome": {"type": "mirror"},
      "glass": {"type": "dielectric", "ior": 1.5}
    },
    "shapes": [
      {"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "chrome"},
      {"type": "sphere", "center": [3, 0, 0], "radius": 1, "material": "glass"},
      {"type": "sphere", "center": [0, 4, 0], "radius": 0.5, "material": "lamp"},
      {"type": "triangles", "material": "white",
       "positions": [[-5,-1,-5],[5,-1,-5],[5,-1,5],[-5,-1,5]], "indices": [0,1,2, 0,2,3]},
      {"type": "triangles", "material": "lamp",
       "positions": [[-1,5,-1],[1,5,-1],[1,5,1],[-1,5,1],[0,6,0]],
       "indices": [0,2,1, 0,3,2, 0,1,4]},
      {"type": "triangles", "material": "wood",
       "positions": [[0,0,3],[1,0,3],[2,0,3]], "indices": [0,1,2]}
    ],
    "lights": [
      {"type": "point", "position": [0, 3, 3], "intensity": [10, 10, 10]},
      {"type": "point", "position": [0, 3, -3], "intensity": [10, 10, 10]},
      {"type": "environment", "radiance": [0.1, 0.1, 0.1]}
    ]
  })");
  CommandResult r = run_cli("info '" + scene + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  std::map<std::string, std::string> m = parse_report(r.out);

  EXPECT_EQ(m["scene"], scene);
  EXPECT_EQ(m["film"], "40x30");
  EXPECT_EQ(m["integrator"], "direct, max_depth 3, spp 9, seed 5");

  EXPECT_EQ(m["filter"], "box, radius 0.5");
  // what the 8-bit outputs apply (it was not shown)
  EXPECT_EQ(m["display"], "gamma 1.8, exposure -1.5, tonemap aces");
  // the shape list's entries by type, then the primitives they made
  EXPECT_EQ(m["shapes"], "6");
  EXPECT_EQ(m["shapes/sphere"], "3");
  EXPECT_EQ(m["shapes/triangles"], "3");
  EXPECT_EQ(m["shapes/mesh"], "0");
  EXPECT_EQ(m["primitives/spheres"], "3");
  // 2 + 3 + 1 triangles; the last is degenerate (collinear corners) and left out of the BVH
  EXPECT_EQ(m["primitives/triangles"], "6 (1 degenerate or non-finite, skipped)");
  EXPECT_EQ(m["primitives/vertices"], "12 (normals 0, uvs 0)");

  EXPECT_EQ(m["materials"], "5");
  EXPECT_EQ(m["materials/diffuse"], "3");
  EXPECT_EQ(m["materials/mirror"], "1");
  EXPECT_EQ(m["materials/dielectric"], "1");
  EXPECT_EQ(m["materials/conductor"], "0");  // every registry type is listed
  EXPECT_EQ(m["materials/plastic"], "0");
  EXPECT_EQ(m["materials/emissive"], "1");

  EXPECT_EQ(m["textures"], "1 (128 B on the device)");
  EXPECT_NE(r.out.find("  4x2  128 B"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("tex.png"), std::string::npos) << r.out;

  // 2 point lights, the environment, the emissive sphere and 3 emissive triangles
  EXPECT_EQ(m["lights"], "7");
  EXPECT_EQ(m["lights/point"], "2");
  EXPECT_EQ(m["lights/sphere"], "1");
  EXPECT_EQ(m["lights/triangle"], "3");
  EXPECT_EQ(m["lights/environment"], "1");
  EXPECT_EQ(m["lights/environment_map"], "0");

  // BVH: 3 spheres + 5 valid triangles. A binary BVH over n primitives in single-primitive or
  // larger leaves has 2 * leaves - 1 nodes, leaves * mean leaf size = n, and depth at least
  // log2(leaves).
  long long prims = leading_int(m["BVH/primitives"]);
  long long nodes = leading_int(m["BVH/nodes"]);
  long long leaves = leading_int(m["BVH/leaves"]);
  long long depth = leading_int(m["BVH/max depth"]);
  EXPECT_EQ(prims, 8);
  EXPECT_GE(leaves, 1);
  EXPECT_EQ(nodes, 2 * leaves - 1);
  EXPECT_GE(depth, static_cast<long long>(std::ceil(std::log2(double(leaves)))));
  EXPECT_LE(depth, leaves);
  double mean = 0;
  size_t max_leaf = 0;
  ASSERT_EQ(std::sscanf(m["BVH/leaf size"].c_str(), "mean %lf, max %zu", &mean, &max_leaf), 2)
      << m["BVH/leaf size"];
  EXPECT_NEAR(mean * leaves, double(prims), 0.01 * leaves);
  EXPECT_GE(double(max_leaf), mean);
  EXPECT_LE(max_leaf, size_t(prims));
  EXPECT_NE(m["BVH/build time"].find(" ms"), std::string::npos);
  EXPECT_GT(std::stod(m["BVH/SAH cost"]), 0.0);

  // the host memory lucent render checks before rendering on a CPU device: its total, and the
  // film's part (40x30 pixels of 80 bytes: 93.75 KiB), as render/resources.cpp estimates them
  EXPECT_NE(m["host memory"].find(" estimated for a render on a CPU device"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("  93.75 KiB   the accumulation and result images of the 40x30 film\n"),
            std::string::npos)
      << r.out;

  // the same numbers as the library's build of the same scene
  lucent::Scene s = lucent::load_scene(scene);
  lucent::render_detail::PackedScene packed = lucent::render_detail::pack_scene(s);
  EXPECT_EQ(size_t(nodes), packed.bvh_stats.binary_nodes);
  // and the wide nodes the binary tree was collapsed into
  size_t wide = 0;
  int width = 0;
  ASSERT_EQ(
      std::sscanf(m["BVH/nodes"].c_str(), "%*d binary, collapsed into %zu %d-wide", &wide, &width),
      2)
      << m["BVH/nodes"];
  EXPECT_EQ(wide, packed.bvh_stats.nodes);
  EXPECT_EQ(width, LC_BVH_WIDTH);
  EXPECT_GE(wide, 1u);
  EXPECT_LE(wide, size_t(nodes));
  EXPECT_EQ(size_t(leaves), packed.bvh_stats.leaves);

  // kernel: where sources come from and the feature defines of this scene
  std::string defines = lucent::render_detail::feature_defines(s, packed);
  // the only shape using the textured material is a degenerate triangle, skipped at packing:
  // nothing samples the texture, so no texture code is compiled (only used materials count)
  EXPECT_EQ(defines.find("-D LC_HAS_TEXTURES"), std::string::npos) << defines;
  EXPECT_NE(defines.find("-D LC_HAS_DIELECTRIC"), std::string::npos) << defines;
  if (!defines.empty() && defines[0] == ' ') defines.erase(0, 1);
  EXPECT_EQ(m["kernel/feature defines"], defines);
  EXPECT_FALSE(m["kernel/sources"].empty());
}

TEST(CliInfo, EmptyScene) {
  std::string scene = lucent::test::temp_dir() + "/empty.json";
  lucent::test::write_file(scene, "{}");
  CommandResult r = run_cli("info '" + scene + "'", "env -u LUCENT_KERNEL_DIR");
  ASSERT_EQ(r.status, 0) << r.err;
  std::map<std::string, std::string> m = parse_report(r.out);
  EXPECT_EQ(m["shapes"], "0");
  EXPECT_EQ(m["primitives/spheres"], "0");
  EXPECT_EQ(m["primitives/triangles"], "0");
  EXPECT_EQ(m["lights"], "0");
  EXPECT_EQ(m["BVH/primitives"], "0");
  EXPECT_EQ(m["BVH/nodes"].substr(0, 2), "0 ");
  EXPECT_EQ(m["kernel/sources"], "embedded");
  lucent::Scene s = lucent::load_scene(scene);
  std::string defines =
      lucent::render_detail::feature_defines(s, lucent::render_detail::pack_scene(s));
  if (!defines.empty() && defines[0] == ' ') defines.erase(0, 1);
  EXPECT_EQ(m["kernel/feature defines"], defines.empty() ? "(none)" : defines);
  // what render adds for each device (render_detail::device_defines): a pass's sums are in
  // double (LC_ACCUM_DOUBLE) on every device with fp64, PoCL's CPU device included, and so are
  // the light sums (LC_LIGHT_DOUBLE) where it also has 64-bit atomics
  EXPECT_EQ(m["kernel/device options"],
            "-D LC_DEVICE_POCL_CPU -D LC_ACCUM_DOUBLE -D LC_LIGHT_DOUBLE on PoCL's CPU device, "
            "-D LC_ACCUM_DOUBLE -D LC_LIGHT_DOUBLE on other devices with fp64 and 64-bit atomics, "
            "-D LC_ACCUM_DOUBLE on those with fp64 only, none on others");
  // --no-specialize: every feature, as the build options line (and Python's scene_info) say;
  // the feature defines line listed the scene's
  r = run_cli("info '" + scene + "' --no-specialize", "env -u LUCENT_KERNEL_DIR");
  ASSERT_EQ(r.status, 0) << r.err;
  m = parse_report(r.out);
  defines = lucent::render_detail::feature_defines(s, lucent::render_detail::pack_scene(s), false);
  if (!defines.empty() && defines[0] == ' ') defines.erase(0, 1);
  EXPECT_NE(defines.find("-D LC_HAS_DIELECTRIC"), std::string::npos) << defines;
  EXPECT_EQ(m["kernel/feature defines"], defines);
  EXPECT_NE(m["kernel/build options"].find(defines), std::string::npos)
      << m["kernel/build options"];
}

// The path integrator's knobs as the render uses them: info printed "clamp 5" and "glass splits 2"
// for a whitted render, which reads neither, splits for a scene without glass, and no caustics
// line at all (integrator.caustics is dropped without a mirror or glass surface).
TEST(CliInfo, IntegratorKnobsSayWhenTheRenderLeavesThemUnused) {
  std::string dir = lucent::test::temp_dir();
  auto info = [&dir](const std::string& material, const std::string& args) {
    lucent::test::write_file(dir + "/s.json", R"({"integrator": {"clamp": 5, "caustics": true},
      "materials": {"m": {"type": ")" + material + R"("}},
      "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}],
      "lights": [{"type": "point", "position": [0, 3, 3], "intensity": [1, 1, 1]}]})");
    CommandResult r = run_cli("info '" + dir + "/s.json' " + args);
    EXPECT_EQ(r.status, 0) << r.err;
    return parse_report(r.out);
  };
  std::map<std::string, std::string> m = info("dielectric", "");
  EXPECT_EQ(m["clamp"], "5");
  EXPECT_EQ(m["caustics"], "on");
  EXPECT_EQ(m["glass splits"], "2");
  m = info("dielectric", "--integrator whitted");
  EXPECT_EQ(m["clamp"], "5 (unused: only the path integrator has it)");
  EXPECT_EQ(m["caustics"], "off (asked for; only the path integrator has it)");
  EXPECT_EQ(m["glass splits"], "2 (unused: only the path integrator has it)");
  m = info("diffuse", "");
  EXPECT_EQ(m["clamp"], "5");
  EXPECT_EQ(m["caustics"], "off (asked for; no mirror or smooth glass surface in the scene)");
  EXPECT_EQ(m["glass splits"], "2 (unused: no smooth glass in the scene)");
  m = info("diffuse", "--no-caustics --dielectric-splits 0 --clamp 0");
  EXPECT_EQ(m["clamp"], "off");
  EXPECT_EQ(m["caustics"], "off");
  EXPECT_EQ(m["glass splits"], "0");
}

// info gives the warnings a render of the scene gives (an albedo above 1, a setting its integrator
// does not read, float's rounding against the small features): it gave only the loader's.
TEST(CliInfo, SaysWhatARenderSays) {
  std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/s.json", R"({"integrator": {"type": "whitted", "rr_depth": 2},
      "materials": {"m": {"type": "diffuse", "albedo": [1.5, 0.5, 0.5]}},
      "shapes": [{"type": "sphere", "center": [1e5, 0, 0], "radius": 0.01, "material": "m"},
                 {"type": "sphere", "center": [1e5, 1, 0], "radius": 0.01, "material": "m"}],
      "lights": [{"type": "point", "position": [1e5, 3, 3], "intensity": [1, 1, 1]}]})");
  for (const std::string& args :
       {std::string("info"), std::string("render --spp 1 -o '") + dir + "/o.png'"}) {
    SCOPED_TRACE(args);
    CommandResult r = run_cli(args + " '" + dir + "/s.json'");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("material 'm': albedo 1.5 in red is above 1"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("/integrator/rr_depth: only the path integrator has it"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("in float precision, rays leave surfaces offset by their rounding"),
              std::string::npos)
        << r.err;
  }
}

// info needs no OpenCL device: it works with every driver hidden.
TEST(CliInfo, NeedsNoOpenClPlatform) {
  std::string dir = lucent::test::temp_dir();
  std::string scene = dir + "/s.json";
  lucent::test::write_file(scene, R"({"materials": {"m": {"type": "diffuse"}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]})");
  CommandResult r = run_cli("info '" + scene + "'", "OCL_ICD_VENDORS='" + dir + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(parse_report(r.out)["BVH/primitives"], "1");
}

TEST(CliInfo, BadSceneIsOneErrorLine) {
  std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/bad.json", R"({"film": {"width": 0}})");
  CommandResult r = run_cli("info '" + dir + "/bad.json'");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err,
            "lucent: error: " + dir + "/bad.json: /film/width: must be in [1, 16384], got 0\n");
  EXPECT_EQ(r.out, "");
  r = run_cli("info");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(lucent::test::count_lines(r.err), 1) << r.err;
}

}  // namespace

}  // namespace test_cli_info
