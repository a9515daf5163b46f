// The OpenCL kernel (lucent::render) against the independent scalar reference
// (lucent::render_reference) on small scenes covering docs/rendering-model.md.
//
// Test: lucent::compare_images with its defaults (docs/compare.md): per pixel-channel
// z = (K - R) / sqrt(var_K / n_K + var_R / n_R + eps^2), eps = 1e-5 + 1e-4 |value|, two-sided,
// Sidak-corrected over all pixel-channels at family-wise alpha = 0.01 (|z| < ~4.65 for 32x32);
// pass when >= 99.5% of the pixels pass and the per-channel image means agree (|z| < 2.93). The
// reference renders with a different seed, so the two images are independent. The negative
// control at the end shows the test's power at these sample counts: a 3% albedo change fails.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "lucent/compare.hpp"
#include "lucent/reference.hpp"
#include "support.hpp"

namespace test_kernel_vs_reference {

namespace {

using lucent::CompareOptions;
using lucent::CompareResult;
using lucent::RenderResult;
using lucent::Scene;

struct Both {
  RenderResult kernel, reference;
  CompareResult cmp;
  /// Whether the reference rendered the samples asked for, which the test's power is sized for.
  bool statistics = true;
};

using lucent::test::scene_from;

// Under AddressSanitizer (CI's second stage, which looks for memory errors) the reference, whose
// instrumented scalar code is most of these tests' time there (PathCausticsSeenInAMirror: 8.5 s
// against 1.7 s in Release), renders a quarter of the samples, and the z-test, sized for the
// whole count, is left to the release build: the same code runs, the verdict is Release's.
constexpr bool kStatistics = !lucent::test::kAddressSanitizer;

Both render_both(Scene scene, int spp, const CompareOptions& options = {}) {
  Both b;
  lucent::RenderOptions ko;
  ko.spp = spp;
  b.kernel = lucent::test::render(scene, ko);
  scene.integrator.seed ^= 0x9e3779b9u;  // independent samples
  lucent::ReferenceOptions ro;
  ro.spp = kStatistics ? spp : std::max(1, spp / 4);
  b.statistics = ro.spp == spp;
  b.reference = lucent::render_reference(scene, ro);
  b.cmp = lucent::compare_images(b.kernel, b.reference, options);
  return b;
}

#define EXPECT_AGREE(b)                                                                  \
  do {                                                                                   \
    if ((b).statistics) {                                                                \
      EXPECT_TRUE((b).cmp.passed) << "A = kernel, B = reference\n" << (b).cmp.summary(); \
    }                                                                                    \
    EXPECT_EQ((b).kernel.nonfinite, 0u);                                                 \
    EXPECT_EQ((b).reference.nonfinite, 0u);                                              \
  } while (0)

/// A 32x32 scene around a floor quad with the given materials, shapes and lights (JSON snippets).
std::string scene_json(const std::string& integrator, const std::string& materials,
                       const std::string& shapes, const std::string& lights,
                       const std::string& camera = "", const std::string& film = "") {
  // one JSON line per source line
  // clang-format off
  return R"({
    "camera": )" + (camera.empty() ? std::string(R"({"position": [0, 1.2, 5], "look_at": [0, 0.4, 0], "fov": 38})") : camera) + R"(,
    "film": )" + (film.empty() ? std::string(R"({"width": 32, "height": 32})") : film) + R"(,
    "integrator": )" + integrator + R"(,
    "materials": {"floor": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]}, )" + materials + R"(},
    "shapes": [{"type": "triangles", "material": "floor",
                "positions": [[-6,0,-6],[6,0,-6],[6,0,6],[-6,0,6]], "indices": [0,2,1, 0,3,2]}, )" +
         shapes + R"(],
    "lights": [)" + lights + R"(]
  })";
  // clang-format on
}

const char* kDiffuseMats = R"("red": {"type": "diffuse", "albedo": [0.8, 0.25, 0.2]},
                              "blue": {"type": "diffuse", "albedo": [0.2, 0.3, 0.8]})";
const char* kSpheres =
    R"({"type": "sphere", "center": [-0.8, 0.6, 0], "radius": 0.6, "material": "red"},
                          {"type": "sphere", "center": [0.9, 0.5, 0.4], "radius": 0.5, "material": "blue"},
                          {"type": "triangles", "material": "blue",
                           "positions": [[-2,0,-1.5],[2,0,-1.5],[0,2,-1.8]], "indices": [0,1,2]})";
const char* kPointLights = R"({"type": "point", "position": [2, 4, 3], "intensity": [30, 28, 25]},
                              {"type": "point", "position": [-3, 2, 1], "intensity": [5, 6, 8]})";
const char* kEnv = R"({"type": "environment", "radiance": [0.25, 0.3, 0.4]})";
const char* kLamps = R"("lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [6, 5, 4]},
                        "panel": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5], "emission": [2, 3, 4]})";
const char* kLampShapes =
    R"({"type": "sphere", "center": [1.2, 2.2, 1.0], "radius": 0.3, "material": "lamp"},
                             {"type": "triangles", "material": "panel",
                              "positions": [[-2.5,2.5,-1],[-1.5,2.5,-1],[-1.5,2.5,0],[-2.5,2.5,0]],
                              "indices": [0,1,2, 0,2,3]})";

// ------------------------------------------------------------------------------------------
// What the first kernel supported: diffuse spheres and triangles, point lights, constant
// environment, mirror, emitters hit by path rays, filters, thin lens.

TEST(KernelVsReference, DirectDiffusePointLights) {
  Both b = render_both(scene_from(scene_json(R"({"type": "direct"})", kDiffuseMats, kSpheres,
                                             std::string(kPointLights) + ", " + kEnv)),
                       128);
  EXPECT_AGREE(b);
}

TEST(KernelVsReference, PathDiffusePointLightsEnvironment) {
  Both b = render_both(scene_from(scene_json(R"({"type": "path", "max_depth": 5})", kDiffuseMats,
                                             kSpheres, std::string(kPointLights) + ", " + kEnv)),
                       256);
  EXPECT_AGREE(b);
}

TEST(KernelVsReference, PathMirror) {
  Both b = render_both(
      scene_from(scene_json(
          R"({"type": "path", "max_depth": 5})",
          std::string(kDiffuseMats) +
              R"(, "mirror": {"type": "mirror", "reflectance": [0.9, 0.8, 0.7]})",
          std::string(kSpheres) +
              R"(, {"type": "sphere", "center": [0, 0.45, 1.2], "radius": 0.45, "material": "mirror"})",
          std::string(kPointLights) + ", " + kEnv)),
      256);
  EXPECT_AGREE(b);
}

// Emitters hit by camera and BSDF rays, and light sampling of spheres and triangles with MIS.
TEST(KernelVsReference, PathAreaLights) {
  Both b = render_both(scene_from(scene_json(R"({"type": "path", "max_depth": 4})",
                                             std::string(kDiffuseMats) + ", " + kLamps,
                                             std::string(kSpheres) + ", " + kLampShapes, "")),
                       256);
  EXPECT_AGREE(b);
}

// Light sampling only (integrator.mis false): the same expected image.
TEST(KernelVsReference, PathAreaLightsWithoutMis) {
  Both b = render_both(scene_from(scene_json(R"({"type": "path", "max_depth": 4, "mis": false})",
                                             std::string(kDiffuseMats) + ", " + kLamps,
                                             std::string(kSpheres) + ", " + kLampShapes, "")),
                       256);
  EXPECT_AGREE(b);
}

// Emission on non-diffuse materials, emitters seen from their back side (dark), a triangle
// emitter facing away from the scene, in a box of walls, with long paths: max_depth 24,
// Russian roulette from the second segment.
TEST(KernelVsReference, LongPathsAndBackFacingEmitters) {
  Both b = render_both(
      scene_from(scene_json(
          R"({"type": "path", "max_depth": 24, "rr_depth": 2})",
          std::string(kDiffuseMats) +
              R"(, "wall": {"type": "diffuse", "albedo": [0.85, 0.8, 0.75]},
                   "glow": {"type": "plastic", "albedo": [0.3, 0.3, 0.3], "roughness": 0.3, "emission": [2, 1, 0.5]},
                   "hot": {"type": "conductor", "specular": [0.9, 0.8, 0.7], "roughness": 0.3, "emission": [0.5, 1, 2]},
                   "panel": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5], "emission": [4, 4, 4]})",
          R"({"type": "sphere", "center": [-0.8, 0.5, 0.2], "radius": 0.5, "material": "glow"},
             {"type": "sphere", "center": [0.8, 0.5, 0.2], "radius": 0.5, "material": "hot"},
             {"type": "triangles", "material": "wall",
              "positions": [[-3,0,-3],[3,0,-3],[3,3,-3],[-3,3,-3],[-3,0,3],[-3,3,3],[3,0,3],[3,3,3]],
              "indices": [0,1,2, 0,2,3,  0,3,5, 0,5,4,  1,6,7, 1,7,2,  3,2,7, 3,7,5]},
             {"type": "triangles", "material": "panel",
              "positions": [[-0.5,2.9,-0.5],[0.5,2.9,-0.5],[0.5,2.9,0.5],[-0.5,2.9,0.5]],
              "indices": [0,1,2, 0,2,3]},
             {"type": "triangles", "material": "panel",
              "positions": [[-1.5,1.2,-1],[-0.5,1.2,-1],[-1,2,-1]], "indices": [0,2,1]})",
          "")),
      256);
  EXPECT_AGREE(b);
}

TEST(KernelVsReference, FilterTent) {
  Scene s = scene_from(
      scene_json(R"({"type": "direct"})", std::string(kDiffuseMats) + ", " + kLamps,
                 std::string(kSpheres) + ", " + kLampShapes, kPointLights, "",
                 R"({"width": 32, "height": 32, "filter": {"type": "tent", "radius": 1.5}})"));
  Both b = render_both(s, 128);
  EXPECT_AGREE(b);
}

TEST(KernelVsReference, FilterGaussian) {
  Scene s = scene_from(
      scene_json(R"({"type": "direct"})", std::string(kDiffuseMats) + ", " + kLamps,
                 std::string(kSpheres) + ", " + kLampShapes, kPointLights, "",
                 R"({"width": 32, "height": 32, "filter": {"type": "gaussian", "radius": 2}})"));
  Both b = render_both(s, 128);
  EXPECT_AGREE(b);
}

TEST(KernelVsReference, FilterWideBox) {
  Scene s = scene_from(
      scene_json(R"({"type": "direct"})", std::string(kDiffuseMats) + ", " + kLamps,
                 std::string(kSpheres) + ", " + kLampShapes, kPointLights, "",
                 R"({"width": 32, "height": 32, "filter": {"type": "box", "radius": 1.25}})"));
  Both b = render_both(s, 128);
  EXPECT_AGREE(b);
}

TEST(KernelVsReference, ThinLens) {
  Scene s = scene_from(scene_json(
      R"({"type": "direct"})", std::string(kDiffuseMats) + ", " + kLamps,
      std::string(kSpheres) + ", " + kLampShapes, kPointLights,
      R"({"position": [0, 1.2, 5], "look_at": [0, 0.4, 0], "fov": 38, "aperture": 0.25, "focus_distance": 4})"));
  Both b = render_both(s, 256);
  EXPECT_AGREE(b);
}

// A thin lens focused far away at a wide angle: the kernel aimed each lens ray at the point
// position + ft dir of the focal plane, ft = focus_distance / cos, which overflowed float towards
// the corners (focus 1e38 at fov 150: a fifth of the pixels rendered rays through infinity,
// without a word). Focused so far, the lens is a pinhole shifted by at most the aperture.
TEST(KernelVsReference, ThinLensFocusedFarAtAWideAngle) {
  Scene s = scene_from(scene_json(
      R"({"type": "direct"})", std::string(kDiffuseMats) + ", " + kLamps,
      std::string(kSpheres) + ", " + kLampShapes, kPointLights,
      R"({"position": [0, 1.2, 5], "look_at": [0, 0.4, 0], "fov": 150, "aperture": 0.1, "focus_distance": 1e38})"));
  Both b = render_both(s, 64);
  EXPECT_AGREE(b);
}

// A non-square film: the scene is asymmetric, so a swapped aspect or a mirrored axis shows.
TEST(KernelVsReference, CameraAspect) {
  Scene s =
      scene_from(scene_json(R"({"type": "direct"})", std::string(kDiffuseMats) + ", " + kLamps,
                            std::string(kSpheres) + ", " + kLampShapes, kPointLights,
                            R"({"position": [0.5, 1.5, 5], "look_at": [0, 0.4, 0], "fov": 40})",
                            R"({"width": 40, "height": 24})"));
  Both b = render_both(s, 32);
  EXPECT_AGREE(b);
}

// Roll: the model turns right and up' counter-clockwise as seen looking along forward (right
// moves towards up'). (The first kernel turned them the other way: roll r matched the reference's
// -r.)
TEST(KernelVsReference, CameraRoll) {
  Scene s = scene_from(
      scene_json(R"({"type": "direct"})", std::string(kDiffuseMats) + ", " + kLamps,
                 std::string(kSpheres) + ", " + kLampShapes, kPointLights,
                 R"({"position": [0.5, 1.5, 5], "look_at": [0, 0.4, 0], "fov": 40, "roll": 25})",
                 R"({"width": 40, "height": 24})"));
  Both b = render_both(s, 32);
  EXPECT_AGREE(b);
}

// Diffuse albedo from a texture: bilinear, repeating, uv (0, 0) at the bottom-left of the image
// (the kernel's convention; the model does not state the lookup), on a quad with uvs and on a
// sphere (its own uv mapping).
TEST(KernelVsReference, TexturedDiffuse) {
  Scene s = scene_from(scene_json(
      R"({"type": "direct"})", std::string(kDiffuseMats) + R"(, "tex": {"type": "diffuse"})",
      std::string(kSpheres) +
          R"(, {"type": "sphere", "center": [0, 0.5, 1.3], "radius": 0.5, "material": "tex"},
        {"type": "triangles", "material": "tex", "positions": [[1,0,-1],[2.5,0,-1],[2.5,1.5,-1],[1,1.5,-1]],
         "uvs": [[0,0],[2,0],[2,2],[0,2]], "indices": [0,1,2, 0,2,3]})",
      std::string(kPointLights) + ", " + kEnv));
  lucent::Texture t;
  t.path = "checker";
  t.width = 4;
  t.height = 3;
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) {
      bool on = (x + y) % 2 == 0;
      t.rgba.insert(t.rgba.end(), {on ? 0.9f : 0.1f, 0.2f + 0.2f * y, 0.1f + 0.2f * x, 1.0f});
    }
  s.textures.push_back(t);
  s.materials[s.find_material("tex")].albedo_texture = 0;
  Both b = render_both(s, 128);
  EXPECT_AGREE(b);
}

// ------------------------------------------------------------------------------------------
// The rest of the model: dielectric, conductor, plastic, whitted, AOVs, environment map,
// shading normals.

TEST(KernelVsReference, PathDielectric) {
  Both b = render_both(
      scene_from(scene_json(
          R"({"type": "path", "max_depth": 8})",
          std::string(kDiffuseMats) + ", " + kLamps +
              R"(, "glass": {"type": "dielectric", "ior": 1.5, "tint": [1, 0.9, 0.8]})",
          std::string(kSpheres) + ", " + kLampShapes +
              R"(, {"type": "sphere", "center": [0.1, 0.5, 1.3], "radius": 0.5, "material": "glass"})",
          kEnv)),
      512);
  EXPECT_AGREE(b);
}

// Rough glass of the largest ior the scene format accepts (MaterialParam::kMaxIor, 20), seen
// from inside: the camera sits off-centre in the sphere, under a uniform sky, so every image
// value comes from light that left through the narrow transmission cone (half-angle about 1/ior)
// that float cosines resolve. The kernel rendered 1.5% dark at ior 100 (image-mean z -5 at
// 24x24, 2048 spp) and 17% at 1000, which the limit, once 1e6, now refuses. At this test's 256k
// samples the image-mean test sees about 3% (ior 100's 1.5% passes here): the range's edge is
// checked at that level, at 0.3% by the measurement at 30 (material_type.hpp).
TEST(KernelVsReference, RoughGlassSeenFromInsideAtTheLargestIor) {
  Both b = render_both(scene_from(R"({
    "camera": {"position": [0.5, 0.3, 0], "look_at": [0.2, 0, -1], "fov": 60},
    "film": {"width": 16, "height": 16},
    "integrator": {"type": "path", "max_depth": 16, "sampler": "independent"},
    "materials": {"glass": {"type": "rough_dielectric", "ior": 20, "roughness": 0.3}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "glass"}],
    "lights": [{"type": "environment", "radiance": [1, 1, 1]}]})"),
                       1024);
  EXPECT_AGREE(b);
}

// Caustics by light tracing (integrator.caustics, docs/rendering-model.md): a glass sphere and
// a mirror sphere under area lights (a sphere lamp, a triangle panel) and a point light (whose
// caustics only light tracing finds), a plastic sphere (a non-delta lobe that light paths end
// on), seen by `camera` (empty: the default pinhole) on the 32 x 32 `film`.
Scene caustics_scene(const std::string& camera, const std::string& film) {
  return scene_from(scene_json(
      R"({"type": "path", "max_depth": 6, "caustics": true})",
      std::string(kDiffuseMats) + ", " + kLamps +
          R"(, "glass": {"type": "dielectric", "ior": 1.5, "tint": [1, 0.9, 0.8]},
                                   "mirror": {"type": "mirror", "reflectance": [0.9, 0.8, 0.7]},
                                   "plastic": {"type": "plastic", "albedo": [0.3, 0.6, 0.3], "roughness": 0.2})",
      std::string(kLampShapes) +
          R"(, {"type": "sphere", "center": [0.1, 0.5, 1.3], "radius": 0.5, "material": "glass"},
                                   {"type": "sphere", "center": [-1.0, 0.4, 0.6], "radius": 0.4, "material": "mirror"},
                                   {"type": "sphere", "center": [1.3, 0.35, 0.2], "radius": 0.35, "material": "plastic"})",
      kPointLights, camera, film));
}

// With a tent filter that splats over 3x3 pixels.
TEST(KernelVsReference, PathCaustics) {
  Both b = render_both(
      caustics_scene("", R"({"width": 32, "height": 32, "filter": {"type": "tent", "radius": 1}})"),
      256);
  EXPECT_AGREE(b);
}

// The same scene through a thin lens out of focus (light paths connect to a point of the lens:
// caustics_connect, LightTracer::connect), with a Gaussian filter. The caustics here are a small
// part of the image: a film position computed from the lens centre instead of the lens point
// passes this test, and fails KernelCaustics.ThinLensPointLightInAMirror (chi-square 7761 for
// 576 pixels), whose closed form is where the lens mapping is checked.
TEST(KernelVsReference, PathCausticsThinLens) {
  Both b = render_both(
      caustics_scene(
          R"({"position": [0, 1.2, 5], "look_at": [0, 0.4, 0], "fov": 38, "aperture": 0.25, "focus_distance": 3})",
          R"({"width": 32, "height": 32, "filter": {"type": "gaussian", "radius": 1.5}})"),
      256);
  EXPECT_AGREE(b);
}

// Light tracing through a thin lens focused far away, from a camera near the floor: a connection
// found its film position from the focal plane's point on the line from the lens point through
// the floor, lens + (x - lens) focus_distance / z, which overflowed float for points less than
// focus_distance / FLT_MAX in front of the lens (0.88 here): their caustic was dropped without a
// word (about 25 of 1024 pixels failed; with the camera rays' own overflow, half the image). The
// caustic: a point light's image in a mirror wall, on the floor in front of the camera.
TEST(KernelVsReference, PathCausticsThinLensFocusedFarNearTheFloor) {
  Scene s = scene_from(R"({
    "camera": {"position": [0, 0.35, 0.3], "look_at": [0, 0, -0.3], "fov": 120, "aperture": 0.02,
               "focus_distance": 3e38},
    "film": {"width": 32, "height": 32},
    "integrator": {"type": "path", "max_depth": 4, "caustics": true},
    "materials": {"floor": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]},
                  "mirror": {"type": "mirror", "reflectance": [0.9, 0.9, 0.9]}},
    "shapes": [{"type": "triangles", "material": "floor",
                "positions": [[-6,0,-6],[6,0,-6],[6,0,6],[-6,0,6]], "indices": [0,2,1, 0,3,2]},
               {"type": "triangles", "material": "mirror",
                "positions": [[-3,0,-1],[3,0,-1],[3,3,-1],[-3,3,-1]], "indices": [0,1,2, 0,2,3]}],
    "lights": [{"type": "point", "position": [0, 0.6, -0.3], "intensity": [3, 3, 3]}]
  })");
  Both b = render_both(s, 64);
  EXPECT_AGREE(b);
}

// Lights inside glass: one refraction between light and floor, where the adjoint weight of a
// light path (no 1 / eta^2) differs from the radiance weight (through a whole sphere the two
// factors cancel). A sphere lamp inside one glass sphere, a point light inside another.
TEST(KernelVsReference, PathCausticsLightsInsideGlass) {
  Both b = render_both(
      scene_from(scene_json(
          R"({"type": "path", "max_depth": 5, "caustics": true})",
          std::string(kDiffuseMats) + ", " + kLamps +
              R"(, "glass": {"type": "dielectric", "ior": 1.5})",
          R"({"type": "sphere", "center": [-0.8, 0.9, 0.5], "radius": 0.6, "material": "glass"},
                               {"type": "sphere", "center": [-0.8, 0.9, 0.5], "radius": 0.15, "material": "lamp"},
                               {"type": "sphere", "center": [0.9, 0.7, 0.2], "radius": 0.5, "material": "glass"})",
          R"({"type": "point", "position": [0.9, 0.7, 0.2], "intensity": [3, 3, 3]})")),
      256);
  EXPECT_AGREE(b);
}

// Light that a caustic sends on (E N N S L, docs/rendering-model.md): a point light under a
// mirror ceiling, a floor that the mirror lights and that a black square shades from the light,
// and a white panel just under the square, facing the floor, which is all the camera sees: its
// light comes only light -> mirror -> floor -> panel, which only light tracing finds (the scene of
// tests/support.hpp's bounced_caustic_scene, as in test_reference_caustics.cpp).
TEST(KernelVsReference, PathCausticsBouncedOffTheFloor) {
  Both b = render_both(
      scene_from(lucent::test::bounced_caustic_scene(
          true, 4,
          R"(], "lights": [{"type": "point", "position": [0, 0, 2.5], "intensity": [4, 4, 4]}])")),
      1024);
  EXPECT_AGREE(b);
  double mean = 0;
  for (float v : b.kernel.mean.rgb) mean += v;
  EXPECT_GT(mean, 0.0) << "the panel is lit only by light tracing";
}

// A caustic seen in mirrors by a diffuse floor (E N S S N S L: floor, mirror wall, mirror
// ceiling, lit floor, mirror ceiling, point light; tests/support.hpp's kMirrorWall), which only
// light paths render: about a quarter of the image, which light paths that end at a delta lobe
// after a non-delta one (the rule before 24 Nov 2026) leave out (image-mean z = -6.7 then, at
// 4096 spp; the threshold is 2.93).
TEST(KernelVsReference, PathCausticsSeenInAMirror) {
  Both b = render_both(
      scene_from(lucent::test::bounced_caustic_scene(
          true, 6,
          R"(], "lights": [{"type": "point", "position": [0, 0, 2.5], "intensity": [4, 4, 4]}])",
          lucent::test::kMirrorWall, lucent::test::kFloorBesideTheMirrorWall)),
      4096);
  EXPECT_AGREE(b);
}

TEST(KernelVsReference, PathConductor) {
  Both b = render_both(
      scene_from(scene_json(
          R"({"type": "path", "max_depth": 5})",
          std::string(kDiffuseMats) + ", " + kLamps +
              R"(, "rough": {"type": "conductor", "specular": [0.95, 0.64, 0.54], "roughness": 0.35},
                   "shiny": {"type": "conductor", "specular": [0.9, 0.9, 0.9], "roughness": 0.08})",
          std::string(kLampShapes) +
              R"(, {"type": "sphere", "center": [-0.7, 0.6, 0.3], "radius": 0.6, "material": "rough"},
                   {"type": "sphere", "center": [0.8, 0.5, 0.6], "radius": 0.5, "material": "shiny"})",
          std::string(kPointLights) + ", " + kEnv)),
      512);
  EXPECT_AGREE(b);
}

TEST(KernelVsReference, PathPlastic) {
  Both b = render_both(
      scene_from(scene_json(
          R"({"type": "path", "max_depth": 5})",
          std::string(kDiffuseMats) + ", " + kLamps +
              R"(, "plastic": {"type": "plastic", "albedo": [0.2, 0.5, 0.8], "specular": [1, 1, 1], "roughness": 0.2, "ior": 1.5},
                   "gloss": {"type": "plastic", "albedo": [0.8, 0.3, 0.1], "roughness": 0.05, "ior": 1.4})",
          std::string(kLampShapes) +
              R"(, {"type": "sphere", "center": [-0.7, 0.6, 0.3], "radius": 0.6, "material": "plastic"},
                   {"type": "sphere", "center": [0.8, 0.5, 0.6], "radius": 0.5, "material": "gloss"})",
          std::string(kPointLights) + ", " + kEnv)),
      512);
  EXPECT_AGREE(b);
}

// diffuse_mirror (a Lambertian base plus a mirror of constant RGB weight): grey, a mirror for red
// that is matte for blue, and a ground quad; area lights, point lights and the sky. The kernel
// chooses the mirror by channel sums and samples the cosine, the reference chooses half-half and
// samples the hemisphere uniformly, so a pdf or lobe-probability mistake on either side differs
// in the mean. `integrator`: the integrator object.
Scene diffuse_mirror_scene(const std::string& integrator) {
  return scene_from(scene_json(
      integrator,
      std::string(kDiffuseMats) + ", " + kLamps +
          R"(, "grey": {"type": "diffuse_mirror", "albedo": [0.5, 0.5, 0.5], "reflectance": [0.4, 0.4, 0.4]},
               "redmirror": {"type": "diffuse_mirror", "albedo": [0.05, 0.3, 0.8], "reflectance": [0.9, 0.5, 0.1]},
               "ground": {"type": "diffuse_mirror", "albedo": [0.3, 0.3, 0.3], "reflectance": [0.2, 0.3, 0.4]})",
      std::string(kLampShapes) +
          R"(, {"type": "sphere", "center": [-0.7, 0.6, 0.3], "radius": 0.6, "material": "grey"},
               {"type": "sphere", "center": [0.8, 0.5, 0.6], "radius": 0.5, "material": "redmirror"},
               {"type": "triangles", "material": "ground",
                "positions": [[-1.5,0.01,1],[1.5,0.01,1],[1.5,0.01,2.5],[-1.5,0.01,2.5]], "indices": [0,2,1, 0,3,2]})",
      std::string(kPointLights) + ", " + kEnv));
}

TEST(KernelVsReference, PathDiffuseMirror) {
  Both b = render_both(diffuse_mirror_scene(R"({"type": "path", "max_depth": 5})"), 256);
  EXPECT_AGREE(b);
}

// Light paths through the mirror lobe of a BSDF that also has a diffuse one: they go on after it
// and connect to the camera at the diffuse part (eval), which the camera path then leaves out.
TEST(KernelVsReference, PathDiffuseMirrorCaustics) {
  Both b = render_both(
      diffuse_mirror_scene(R"({"type": "path", "max_depth": 5, "caustics": true})"), 256);
  EXPECT_AGREE(b);
}

// Whitted (the diffuse part under point lights plus reflectance x the mirror ray), direct (the
// point lights through the diffuse part) and the albedo AOV (albedo + reflectance).
TEST(KernelVsReference, DiffuseMirrorWhittedDirectAlbedo) {
  for (const char* integrator : {"whitted", "direct", "albedo"}) {
    SCOPED_TRACE(integrator);
    Both b = render_both(
        diffuse_mirror_scene(R"({"type": ")" + std::string(integrator) + R"(", "max_depth": 6})"),
        16);
    EXPECT_AGREE(b);
  }
}

TEST(KernelVsReference, DirectGlossy) {
  Both b = render_both(
      scene_from(scene_json(
          R"({"type": "direct"})",
          std::string(kDiffuseMats) +
              R"(, "plastic": {"type": "plastic", "albedo": [0.2, 0.5, 0.8], "roughness": 0.3},
                   "metal": {"type": "conductor", "specular": [0.95, 0.64, 0.54], "roughness": 0.4})",
          R"({"type": "sphere", "center": [-0.7, 0.6, 0.3], "radius": 0.6, "material": "plastic"},
             {"type": "sphere", "center": [0.8, 0.5, 0.6], "radius": 0.5, "material": "metal"})",
          kPointLights)),
      64);
  EXPECT_AGREE(b);
}

TEST(KernelVsReference, Whitted) {
  Both b = render_both(
      scene_from(scene_json(
          R"({"type": "whitted", "max_depth": 6})",
          std::string(kDiffuseMats) + ", " + kLamps +
              R"(, "glass": {"type": "dielectric", "ior": 1.5, "tint": [1, 0.9, 0.8]},
                   "mirror": {"type": "mirror", "reflectance": [0.9, 0.8, 0.7]},
                   "metal": {"type": "conductor", "specular": [0.95, 0.64, 0.54], "roughness": 0.2},
                   "plastic": {"type": "plastic", "albedo": [0.2, 0.5, 0.8], "roughness": 0.2})",
          std::string(kLampShapes) +
              R"(, {"type": "sphere", "center": [-1.2, 0.5, 0.3], "radius": 0.5, "material": "glass"},
                   {"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5, "material": "mirror"},
                   {"type": "sphere", "center": [1.2, 0.5, 0.3], "radius": 0.5, "material": "metal"},
                   {"type": "sphere", "center": [0.3, 0.3, 1.4], "radius": 0.3, "material": "plastic"})",
          std::string(kPointLights) + ", " + kEnv)),
      64);
  EXPECT_AGREE(b);
}

// A point light exactly on a surface (at ceiling height, a common hand-written scene): the
// direct and Whitted integrators' shadow rays went from the offset origin to the light's full
// distance and met the ceiling it lies on; the floor lost 43% of its light (image-mean z -55),
// and a light in a quad's plane lit nothing. The path integrator and the reference stop short.
TEST(KernelVsReference, DirectAndWhittedPointLightOnTheCeiling) {
  for (const char* integrator :
       {R"({"type": "direct"})", R"({"type": "whitted", "max_depth": 4})"}) {
    SCOPED_TRACE(integrator);
    Both b = render_both(scene_from(std::string(R"({
      "camera": {"position": [0, 1, 3.5], "look_at": [0, 1, 0], "fov": 50},
      "film": {"width": 32, "height": 32},
      "integrator": )") + integrator +
                                    R"(,
      "materials": {"w": {"type": "diffuse", "albedo": [0.7, 0.7, 0.7]}},
      "shapes": [
        {"type": "triangles", "material": "w", "positions": [[-1,0,-1],[1,0,-1],[1,0,1],[-1,0,1]], "indices": [0,3,2, 0,2,1]},
        {"type": "triangles", "material": "w", "positions": [[-1,2,-1],[1,2,-1],[1,2,1],[-1,2,1]], "indices": [0,1,2, 0,2,3]},
        {"type": "triangles", "material": "w", "positions": [[-1,0,-1],[1,0,-1],[1,2,-1],[-1,2,-1]], "indices": [0,1,2, 0,2,3]}],
      "lights": [{"type": "point", "position": [0, 2, 0], "intensity": [3, 3, 3]}]})"),
                         16);
    EXPECT_AGREE(b);
  }
}

// max_depth counts segments in Whitted too: 1 shows what the camera sees emit (emitters and the
// environment), 2 adds the point lights' direct light and one mirror bounce's emitters, 3 the
// point-lit floor in the mirror. The kernel once lit the last segment's surfaces by the point
// lights as well (a whole extra level of direct light; at max_depth 1 every diffuse pixel).
TEST(KernelVsReference, WhittedShortPaths) {
  for (int depth : {1, 2, 3}) {
    SCOPED_TRACE("max_depth " + std::to_string(depth));
    Both b = render_both(
        scene_from(scene_json(
            R"({"type": "whitted", "max_depth": )" + std::to_string(depth) + "}",
            std::string(kDiffuseMats) + ", " + kLamps +
                R"(, "mirror": {"type": "mirror", "reflectance": [0.9, 0.8, 0.7]})",
            std::string(kSpheres) + ", " + kLampShapes +
                R"(, {"type": "sphere", "center": [0, 0.45, 1.2], "radius": 0.45, "material": "mirror"})",
            std::string(kPointLights) + ", " + kEnv)),
        32);
    EXPECT_AGREE(b);
  }
}

// Every material's albedo AOV, normals, depth and ambient occlusion (bounded and unbounded),
// statistically (the box filter jitters the first hit).
TEST(KernelVsReference, Aovs) {
  std::string mats = std::string(kDiffuseMats) +
                     R"(, "glass": {"type": "dielectric", "tint": [1, 0.9, 0.8]},
                          "mirror": {"type": "mirror", "reflectance": [0.9, 0.8, 0.7]},
                          "metal": {"type": "conductor", "specular": [0.95, 0.64, 0.54]},
                          "plastic": {"type": "plastic", "albedo": [0.2, 0.5, 0.8]})";
  std::string shapes =
      std::string(kSpheres) +
      R"(, {"type": "sphere", "center": [-1.5, 0.3, 1.2], "radius": 0.3, "material": "glass"},
                            {"type": "sphere", "center": [0, 0.3, 1.4], "radius": 0.3, "material": "mirror"},
                            {"type": "sphere", "center": [1.5, 0.3, 1.2], "radius": 0.3, "material": "metal"},
                            {"type": "sphere", "center": [0.3, 1.5, -0.5], "radius": 0.3, "material": "plastic"})";
  for (const char* integrator :
       {R"({"type": "albedo"})", R"({"type": "normal"})", R"({"type": "depth"})",
        R"({"type": "ao"})", R"({"type": "ao", "ao_distance": 0.5})"}) {
    SCOPED_TRACE(integrator);
    Both b = render_both(scene_from(scene_json(integrator, mats, shapes, kEnv)), 64);
    EXPECT_AGREE(b);
  }
}

// Depth and normal with a vanishing filter radius are deterministic: agreement within a
// tolerance of ~4.65 * (1e-4 + 1e-4 |value|) on 99.5% of the pixels (a pixel centre may graze a
// silhouette).
TEST(KernelVsReference, DepthAndNormalDeterministic) {
  CompareOptions o;
  o.abs_epsilon = 1e-4;
  o.rel_epsilon = 1e-4;
  for (const char* integrator : {R"({"type": "normal"})", R"({"type": "depth"})"}) {
    SCOPED_TRACE(integrator);
    Scene s = scene_from(
        scene_json(integrator, kDiffuseMats, kSpheres, "", "",
                   R"({"width": 32, "height": 32, "filter": {"type": "box", "radius": 1e-6}})"));
    Both b = render_both(s, 1, o);
    EXPECT_AGREE(b);
    EXPECT_LT(b.cmp.max_abs_error, 0.01) << b.cmp.summary();
  }
}

// Vertex normals far from unit length, set directly (Scene.normals: the loaders and the builder
// store unit ones): the shading normal is their interpolation's direction, whatever their
// length. Normals of 1e-50 became 0 in the kernel's float, which then shaded with the geometric
// normal while the reference used theirs (the API tester's find); 1e30 squared overflowed float.
TEST(KernelVsReference, VertexNormalsOfAnyLength) {
  CompareOptions o;
  o.abs_epsilon = 1e-4;
  o.rel_epsilon = 1e-4;
  Scene unit = scene_from(scene_json(
      R"({"type": "normal"})", kDiffuseMats,
      R"({"type": "triangles", "material": "red",
          "positions": [[-1,0.2,0],[1,0.2,0],[0,1.4,0]], "indices": [0,1,2],
          "normals": [[-0.6,0,0.8],[0.6,0,0.8],[0,0.6,0.8]]})",
      "", "", R"({"width": 16, "height": 16, "filter": {"type": "box", "radius": 1e-6}})"));
  lucent::RenderOptions ko;
  ko.spp = 1;
  const RenderResult expected = lucent::test::render(unit, ko);
  for (double scale : {1e-310, 1e-50, 1e-20, 1e20, 1e30}) {
    SCOPED_TRACE(scale);
    Scene s = unit;
    for (glm::dvec3& n : s.normals) n *= scale;
    const RenderResult k = lucent::test::render(s, ko);
    ASSERT_EQ(k.mean.rgb.size(), expected.mean.rgb.size());
    double worst = 0;
    for (size_t i = 0; i < k.mean.rgb.size(); ++i)
      worst = std::max(worst, double(std::abs(k.mean.rgb[i] - expected.mean.rgb[i])));
    EXPECT_LT(worst, 1e-6);
    Both b = render_both(s, 1, o);
    EXPECT_AGREE(b);
  }
}

// An equirectangular environment map (nearest texels) lighting a diffuse and a glossy sphere,
// seen directly too.
TEST(KernelVsReference, EnvironmentMap) {
  Scene s = scene_from(scene_json(
      R"({"type": "path", "max_depth": 4})",
      std::string(kDiffuseMats) +
          R"(, "plastic": {"type": "plastic", "albedo": [0.2, 0.5, 0.8], "roughness": 0.3})",
      R"({"type": "sphere", "center": [-0.7, 0.6, 0.3], "radius": 0.6, "material": "red"},
         {"type": "sphere", "center": [0.8, 0.5, 0.6], "radius": 0.5, "material": "plastic"})",
      "", R"({"position": [0, 1.5, 5], "look_at": [0, 0.6, 0], "fov": 60})"));
  lucent::Texture t;
  t.path = "sky";
  t.width = 16;
  t.height = 8;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x) {
      float sun = (x == 3 && y == 2) ? 40.0f : 0.0f;
      t.rgba.insert(t.rgba.end(),
                    {0.2f + 0.05f * x + sun, 0.3f + 0.1f * (7 - y), 0.5f + sun, 1.0f});
    }
  s.textures.push_back(t);
  lucent::Light env;
  env.type = lucent::LightType::EnvironmentMap;
  env.radiance = glm::dvec3(0.8);
  env.texture = 0;
  s.lights.push_back(env);
  Both b = render_both(s, 256);
  EXPECT_AGREE(b);
}

// Interpolated vertex normals on a coarse mesh (an octahedron with normals pointing away from its
// centre): shading normals differ from geometric ones, and light can arrive below the geometric
// surface.
TEST(KernelVsReference, ShadingNormals) {
  Both b = render_both(
      scene_from(scene_json(
          R"({"type": "path", "max_depth": 4})",
          std::string(kDiffuseMats) + ", " + kLamps +
              R"(, "plastic": {"type": "plastic", "albedo": [0.2, 0.5, 0.8], "roughness": 0.25})",
          std::string(kLampShapes) + R"(,
            {"type": "triangles", "material": "red",
             "positions": [[-1.6,0.7,0],[-0.8,0.7,0],[-1.2,1.1,0],[-1.2,0.3,0],[-1.2,0.7,0.4],[-1.2,0.7,-0.4]],
             "normals": [[-1,0,0],[1,0,0],[0,1,0],[0,-1,0],[0,0,1],[0,0,-1]],
             "indices": [0,4,2, 4,1,2, 1,5,2, 5,0,2, 4,0,3, 1,4,3, 5,1,3, 0,5,3]},
            {"type": "triangles", "material": "plastic",
             "positions": [[0.4,0.7,0.3],[1.2,0.7,0.3],[0.8,1.1,0.3],[0.8,0.3,0.3],[0.8,0.7,0.7],[0.8,0.7,-0.1]],
             "normals": [[-1,0,0],[1,0,0],[0,1,0],[0,-1,0],[0,0,1],[0,0,-1]],
             "indices": [0,4,2, 4,1,2, 1,5,2, 5,0,2, 4,0,3, 1,4,3, 5,1,3, 0,5,3]})",
          std::string(kPointLights) + ", " + kEnv)),
      256);
  EXPECT_AGREE(b);
}

// Smooth and rough glass on meshes whose vertex normals disagree with their faces (the octahedra
// of ShadingNormals): a direction that crosses the geometric surface on the wrong side of what its
// lobe says (a reflection below it, a refraction above it) carries nothing, both when the BSDF
// samples it and when light sampling finds it (docs/rendering-model.md, "Materials"). The
// reference once followed such smooth-glass directions (10 pixels of the first image failed), and
// the kernel's light sampling once took the rough glass's reflection value for a light behind the
// geometric surface (the second image's mean z was 141).
TEST(KernelVsReference, ShadingNormalsOnGlass) {
  const std::string octahedron =
      R"("positions": [[-0.4,0,0],[0.4,0,0],[0,0.4,0],[0,-0.4,0],[0,0,0.4],[0,0,-0.4]],
         "normals": [[-1,0,0],[1,0,0],[0,1,0],[0,-1,0],[0,0,1],[0,0,-1]],
         "indices": [0,4,2, 4,1,2, 1,5,2, 5,0,2, 4,0,3, 1,4,3, 5,1,3, 0,5,3])";
  auto at = [&](double x, double y, double z, const char* material) {
    std::string m = R"({"type": "triangles", "material": ")" + std::string(material) +
                    R"(", "transform": [{"translate": [)" + std::to_string(x) + ", " +
                    std::to_string(y) + ", " + std::to_string(z) + "]}], " + octahedron + "}";
    return m;
  };
  Both b = render_both(
      scene_from(scene_json(R"({"type": "path", "max_depth": 6})",
                            std::string(kDiffuseMats) + ", " + kLamps +
                                R"(, "glass": {"type": "dielectric", "ior": 1.5},
                   "frosted": {"type": "rough_dielectric", "ior": 1.5, "roughness": 0.3})",
                            std::string(kLampShapes) + ", " + at(-0.8, 0.7, 0.3, "glass") + ", " +
                                at(0.8, 0.7, 0.3, "frosted"),
                            std::string(kPointLights) + ", " + kEnv)),
      256);
  EXPECT_AGREE(b);
  // A rough glass quad whose shading normals lean 45 degrees towards -x, and a point light below
  // its plane but above the shading normals' plane (at -x): light sampling must not take the
  // reflection lobe's value for it (the kernel once did, with a shadow ray from behind). A second
  // point light above both planes lights the quad as usual.
  SCOPED_TRACE("rough glass quad, a light in the wedge between its two planes");
  b = render_both(scene_from(R"({
        "camera": {"position": [0, 3, 3], "look_at": [0, 0, 0], "fov": 40},
        "film": {"width": 24, "height": 24},
        "integrator": {"type": "path", "max_depth": 3},
        "materials": {"frosted": {"type": "rough_dielectric", "ior": 1.5, "roughness": 0.3}},
        "shapes": [{"type": "triangles", "material": "frosted",
                    "positions": [[-1,0,-1],[1,0,-1],[1,0,1],[-1,0,1]],
                    "normals": [[-0.7,0.7,0],[-0.7,0.7,0],[-0.7,0.7,0],[-0.7,0.7,0]],
                    "indices": [0,2,1, 0,3,2]}],
        "lights": [{"type": "point", "position": [-6, -0.5, 0], "intensity": [30, 30, 30]},
                   {"type": "point", "position": [-1, 3, 1], "intensity": [2, 2, 2]}]
      })"),
                  64);
  EXPECT_AGREE(b);
}

// A floor that is a sphere of radius 1000 (as in scenes/default.json) lit by a sphere light only.
// Large primitives need large ray offsets; a shadow ray from an offset origin must not let the
// light's own sphere hide the sampled point near its silhouette (the first kernel, and the first
// reference, were 5% and 20% too dark here; ReferenceAnalytic.SphericalEmitterIrradiance checks
// the same kind of floor against the closed form).
TEST(KernelVsReference, LargeSphereFloorUnderSphereLight) {
  Both b = render_both(scene_from(R"({
        "camera": {"position": [0, 1.2, 8], "look_at": [0, 0.6, 0], "fov": 35},
        "film": {"width": 32, "height": 24},
        "integrator": {"type": "path", "max_depth": 2},
        "materials": {"floor": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]},
                      "sky": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [6, 5.5, 5]}},
        "shapes": [{"type": "sphere", "center": [0, -1000, 0], "radius": 1000, "material": "floor"},
                   {"type": "sphere", "center": [-6, 9, 3], "radius": 1.5, "material": "sky"}]
      })"),
                       256);
  EXPECT_AGREE(b);
}

// Negative control: the same scene with the floor's albedo 3% lower in the reference must fail.
TEST(KernelVsReference, DetectsAThreePercentAlbedoChange) {
  if (!kStatistics) GTEST_SKIP() << "the test's power is checked in the release build";
  Scene s = scene_from(scene_json(R"({"type": "path", "max_depth": 5})", kDiffuseMats, kSpheres,
                                  std::string(kPointLights) + ", " + kEnv));
  lucent::RenderOptions ko;
  ko.spp = 256;
  RenderResult k = lucent::test::render(s, ko);
  s.integrator.seed ^= 0x9e3779b9u;
  s.materials[s.find_material("floor")].albedo *= 0.97;
  lucent::ReferenceOptions ro;
  ro.spp = 256;
  RenderResult r = lucent::render_reference(s, ro);
  CompareResult c = lucent::compare_images(k, r);
  EXPECT_FALSE(c.passed) << c.summary();
}

}  // namespace

// Primary-hit primitive ids, deterministic: the kernel and the reference see the same camera
// rays (shared sample indexing, the same seed, a vanishing box filter) and must name the same
// primitive (scene order: spheres, then the scene's triangle list) in every pixel but a few at
// silhouettes, where float and double may round to different sides. A degenerate triangle comes
// first in the list, so the kernel's packed index (which drops it) differs from the scene index.
TEST(KernelVsReference, PrimitiveIdDeterministic) {
  Scene s = scene_from(R"({
    "camera": {"position": [0, 1.2, 5], "look_at": [0, 0.5, 0], "fov": 45},
    "film": {"width": 48, "height": 32, "filter": {"type": "box", "radius": 1e-6}},
    "integrator": {"type": "primitive", "seed": 9},
    "materials": {"m": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
    "shapes": [
      {"type": "triangles", "material": "m", "positions": [[0,0,0],[1,0,0],[2,0,0]], "indices": [0,1,2]},
      {"type": "sphere", "center": [-0.8, 0.5, 0], "radius": 0.5, "material": "m"},
      {"type": "sphere", "center": [0.9, 0.4, 0.3], "radius": 0.4, "material": "m"},
      {"type": "triangles", "material": "m",
       "positions": [[-3,0,-3],[3,0,-3],[3,0,3],[-3,0,3],[-1,0,-1],[1,0,-1],[0,1.5,-1]],
       "indices": [0,2,1, 0,3,2, 4,5,6]}]})");
  lucent::RenderOptions ko;
  ko.spp = 1;
  lucent::RenderResult k = lucent::test::render(s, ko);
  lucent::ReferenceOptions ro;
  ro.spp = 1;
  lucent::RenderResult r = lucent::render_reference(s, ro);
  ASSERT_EQ(k.mean.rgb.size(), r.mean.rgb.size());
  int differ = 0, seen[7] = {0, 0, 0, 0, 0, 0, 0};
  for (size_t i = 0; i < k.mean.rgb.size(); i += 3) {
    float a = k.mean.rgb[i], b = r.mean.rgb[i];
    ASSERT_EQ(a, std::floor(a)) << "not an id: " << a;
    if (a != b) ++differ;
    if (a >= 0 && a < 7) ++seen[int(a)];
  }
  const size_t pixels = k.mean.rgb.size() / 3;
  EXPECT_LE(differ, int(pixels / 200))
      << differ << " of " << pixels << " pixels name another primitive";
  // misses (0), both spheres (1, 2), the floor (4, 5: triangles 1 and 2 of the list) and the
  // standing triangle (6) are all in view; the degenerate triangle (3) never is
  for (int id : {0, 1, 2, 4, 5, 6}) EXPECT_GT(seen[id], 0) << "id " << id;
  EXPECT_EQ(seen[3], 0);
}

}  // namespace test_kernel_vs_reference

// (the next file of its unity batch may define its own)
#undef EXPECT_AGREE
