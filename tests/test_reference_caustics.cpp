// Caustics by light tracing in the reference integrator (integrator.caustics,
// docs/rendering-model.md, "Caustics by light tracing"), against closed-form answers and against
// the path integrator alone. Statistical checks: lucent::compare_images (per pixel-channel
// z = (A - B) / sqrt(var_A / n_A + var_B / n_B + eps^2), Sidak-corrected at family-wise
// alpha = 0.01, |z| < ~4.5 for 32x24 pixels; 99.5% of the pixels must pass, and the image means
// per channel must agree, |z| < 2.93), plus, where stated, a z-test of a region's mean.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "lucent/compare.hpp"
#include "lucent/reference.hpp"
#include "support.hpp"

namespace test_reference_caustics {

namespace {

using glm::dvec3;
using lucent::RenderResult;

// Under AddressSanitizer (CI's second stage) the reference runs 4-5 times slower, and the
// renders of 1024-2048 samples per pixel below took 4-6 s each there. There they render a
// sixteenth of the samples (`samples`), which runs the same code for the sanitizers, and their
// statistical checks, sized for the whole count, run in the release build only (`kStatistics`).
constexpr bool kStatistics = !lucent::test::kAddressSanitizer;
int samples(int spp) { return kStatistics ? spp : std::max(1, spp / 16); }

RenderResult render_ref(const std::string& json, int spp) {
  lucent::Scene scene = lucent::test::scene_from(json);  // independent sampler
  lucent::ReferenceOptions o;
  o.spp = spp;
  return lucent::render_reference(scene, o);
}

// A point light of intensity I at (lx, ly, lz) between a diffuse floor z = 0 of albedo a and a
// mirror ceiling z = 2 (reflectance 1, x, y within +-3, facing down). The camera looks straight
// down from (0, 0, 1.9), fov 60, at the floor x, y within about +-1.46, +-1.1 (it sees no
// ceiling). With max_depth 3 the path integrator renders direct light only (its BSDF rays reach
// the ceiling, never the point light); light tracing adds the light reflected by the ceiling,
// which is the light of the mirror image (lx, ly, 4 - lz):
//   L(p) = a / pi * I * (cos1 / d1^2 + cos2 / d2^2).
// About 5% of the light paths reach the floor that the camera sees through the ceiling, so a
// render of n samples per pixel has about n / 20 light-path hits per pixel.
constexpr double kAlbedo = 0.5, kI = 4, kLx = 0.3, kLy = 0.2, kLz = 1.2, kCeiling = 2;
constexpr int kW = 32, kH = 24;
const double kTanHalf = std::tan(30 * M_PI / 180);  // fov 60
const dvec3 kCamera(0, 0, 1.9);

// `lens`: more of the camera's settings (a thin lens).
std::string mirror_scene(bool caustics, const std::string& filter, const std::string& lens = "") {
  return std::string(R"({
    "camera": {"position": [0, 0, 1.9], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 60)") +
         lens + R"(},
    "film": {"width": 32, "height": 24, "filter": )" +
         filter + R"(},
    "integrator": {"type": "path", "max_depth": 3, "caustics": )" +
         (caustics ? "true" : "false") + R"(},
    "materials": {"floor": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]},
                  "mirror": {"type": "mirror", "reflectance": [1, 1, 1]}},
    "shapes": [{"type": "triangles", "material": "floor",
                "positions": [[-10,-10,0],[10,-10,0],[10,10,0],[-10,10,0]],
                "indices": [0,1,2, 0,2,3]},
               {"type": "triangles", "material": "mirror",
                "positions": [[-3,-3,2],[3,-3,2],[3,3,2],[-3,3,2]],
                "indices": [0,2,1, 0,3,2]}],
    "lights": [{"type": "point", "position": [0.3, 0.2, 1.2], "intensity": [4, 4, 4]}]
  })";
}

/// The floor point that film position (fx, fy) sees, from the model's camera basis (here
/// forward -z, right +x, up +y).
glm::dvec2 floor_point(double fx, double fy) {
  const dvec3 fwd(0, 0, -1), right = glm::normalize(glm::cross(fwd, dvec3(0, 1, 0)));
  const dvec3 up = glm::cross(right, fwd);
  double nx = (2 * fx / kW - 1) * kTanHalf * kW / kH, ny = (1 - 2 * fy / kH) * kTanHalf;
  dvec3 d = fwd + nx * right + ny * up;
  dvec3 p = kCamera + (kCamera.z / -d.z) * d;  // z = 0
  return glm::dvec2(p.x, p.y);
}

/// The floor's radiance at p: direct light, plus the mirror image's when `mirror`. Checks that
/// the ceiling really reflects there: the ray from p to the image crosses z = 2 inside it.
double floor_radiance(glm::dvec2 p, bool mirror) {
  auto term = [&](double lz) {
    double dx = kLx - p.x, dy = kLy - p.y, d2 = dx * dx + dy * dy + lz * lz;
    return lz / std::sqrt(d2) / d2;
  };
  double e = term(kLz);
  if (mirror) {
    const double iz = 2 * kCeiling - kLz;  // the mirror image of the light
    const double t = kCeiling / iz;
    const glm::dvec2 q = p + t * (glm::dvec2(kLx, kLy) - p);
    EXPECT_TRUE(std::abs(q.x) < 3 && std::abs(q.y) < 3) << p.x << " " << p.y;
    e += term(iz);
  }
  return kAlbedo / M_PI * kI * e;
}

/// Expected image: each pixel the mean of the floor's radiance over the film positions that its
/// filter draws, by a midpoint rule over [-r, r]^2 weighted by the filter's (unnormalized)
/// shape `w`, normalized here. With a thin lens of radius `aperture` focused at `focus`, also
/// the mean over the lens (6 rings of equal area times 12 angles): the camera ray of film
/// position f and lens offset l aims at the point of the focal plane that the pinhole ray of f
/// crosses, and meets the floor at floor_point(f) + l (1 - 1.9 / focus).
RenderResult expected_image(const RenderResult& like, bool mirror, double r,
                            const std::function<double(double, double)>& w, double aperture = 0,
                            double focus = 1) {
  RenderResult e;
  e.mean = like.mean;
  const int n = aperture > 0 ? 8 : 24;
  const int rings = aperture > 0 ? 6 : 1, angles = aperture > 0 ? 12 : 1;
  std::vector<glm::dvec2> lens;
  for (int k = 0; k < rings; ++k)
    for (int a = 0; a < angles; ++a) {
      double lr = aperture * std::sqrt((k + 0.5) / rings), phi = 2 * M_PI * (a + 0.5) / angles;
      lens.push_back(lr * (1 - kCamera.z / focus) * glm::dvec2(std::cos(phi), std::sin(phi)));
    }
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      double sum = 0, wsum = 0;
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          double ox = r * (2 * (i + 0.5) / n - 1), oy = r * (2 * (j + 0.5) / n - 1);
          double wi = w(ox, oy);
          if (wi <= 0) continue;
          for (const glm::dvec2& l : lens) {
            sum += wi * floor_radiance(floor_point(x + 0.5 + ox, y + 0.5 + oy) + l, mirror);
            wsum += wi;
          }
        }
      for (int c = 0; c < 3; ++c) e.mean.pixel(x, y)[c] = static_cast<float>(sum / wsum);
    }
  return e;
}

double box_shape(double, double) { return 1; }

// Caustics on, box filter: the floor shows the light and its mirror image (a caustic of a point
// light, which only light tracing finds). Default comparison (see the top of the file); 2048
// samples per pixel, about 100 light-path hits per pixel.
TEST(ReferenceCaustics, PointLightMirrorImage) {
  RenderResult r = render_ref(mirror_scene(true, R"({"type": "box"})"), samples(2048));
  EXPECT_EQ(r.nonfinite, 0u);
  if (!kStatistics) return;
  lucent::CompareResult c = lucent::compare_images(r, expected_image(r, true, 0.5, box_shape));
  EXPECT_TRUE(c.passed) << c.summary();
}

// Caustics off: the path integrator cannot reach a point light through a mirror, so the floor
// shows the direct light only; the same render does not match the image with the mirror term,
// so the test above tests something.
TEST(ReferenceCaustics, PointLightMirrorImageAbsentWithoutCaustics) {
  RenderResult r = render_ref(mirror_scene(false, R"({"type": "box"})"), 64);
  lucent::CompareResult direct =
      lucent::compare_images(r, expected_image(r, false, 0.5, box_shape));
  EXPECT_TRUE(direct.passed) << direct.summary();
  lucent::CompareResult with_mirror =
      lucent::compare_images(r, expected_image(r, true, 0.5, box_shape));
  EXPECT_FALSE(with_mirror.passed) << with_mirror.summary();
}

// The light tracer spreads a connection over every pixel whose filter reaches it, weighted by the
// filter's normalized density: tent (radius 1) and gaussian (radius 1.5, sigma 0.5, truncated)
// against the expected image built from their shapes alone. Default comparison.
TEST(ReferenceCaustics, PointLightMirrorImageFilters) {
  {
    SCOPED_TRACE("tent");
    RenderResult r =
        render_ref(mirror_scene(true, R"({"type": "tent", "radius": 1})"), samples(1024));
    EXPECT_EQ(r.nonfinite, 0u);
    auto tent = [](double x, double y) { return (1 - std::abs(x)) * (1 - std::abs(y)); };
    if (kStatistics) {
      lucent::CompareResult c = lucent::compare_images(r, expected_image(r, true, 1, tent));
      EXPECT_TRUE(c.passed) << c.summary();
    }
  }
  {
    SCOPED_TRACE("gaussian");
    RenderResult r =
        render_ref(mirror_scene(true, R"({"type": "gaussian", "radius": 1.5})"), samples(1024));
    EXPECT_EQ(r.nonfinite, 0u);
    auto gauss = [](double x, double y) {
      double r2 = x * x + y * y;
      return r2 <= 1.5 * 1.5 ? std::exp(-r2 / (2 * 0.5 * 0.5)) : 0.0;
    };
    if (kStatistics) {
      lucent::CompareResult c = lucent::compare_images(r, expected_image(r, true, 1.5, gauss));
      EXPECT_TRUE(c.passed) << c.summary();
    }
  }
}

// Light tracing through a thin lens (LightTracer::connect, CameraModel::project_lens): the
// mirror scene out of focus (aperture 0.8, focused at 4 for the floor's 1.9: every floor point
// spreads over a disk of radius 0.42, 4.6 pixels) against the closed form averaged over the lens
// as well. Default comparison; power: the same render against the image in focus fails (31
// pixels, image-mean z -21.6, when written).
TEST(ReferenceCaustics, ThinLensPointLightMirrorImage) {
  RenderResult r = render_ref(
      mirror_scene(true, R"({"type": "box"})", R"(, "aperture": 0.8, "focus_distance": 4)"),
      samples(2048));
  EXPECT_EQ(r.nonfinite, 0u);
  if (!kStatistics) return;
  lucent::CompareResult c =
      lucent::compare_images(r, expected_image(r, true, 0.5, box_shape, 0.8, 4));
  EXPECT_TRUE(c.passed) << c.summary();
  lucent::CompareResult focused =
      lucent::compare_images(r, expected_image(r, true, 0.5, box_shape));
  EXPECT_FALSE(focused.passed) << focused.summary();
}

/// Mean over the pixels x0 <= x < x1, y0 <= y < y1 of channel 1, and the variance of that mean
/// (the pixels' variance / n summed, over the count squared).
struct RegionMean {
  double mean = 0, var = 0;
};
RegionMean region_mean(const RenderResult& r, int x0, int x1, int y0, int y1) {
  RegionMean m;
  double k = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const size_t i = static_cast<size_t>(y) * r.mean.width + x;
      m.mean += r.mean.pixel(x, y)[1];
      m.var += r.variance.pixel(x, y)[1] / r.samples[i];
      ++k;
    }
  m.mean /= k;
  m.var /= k * k;
  return m;
}

/// Caustics on (light tracing the caustic paths, the path integrator the rest) and off (the path
/// integrator alone, finding the caustics by BSDF sampling through the glass) estimate the same
/// image (with max_depth 6 the light paths go on after their first connection, through further
/// non-delta vertices). `scene(caustics, max_depth)` is rendered with both at 256 samples per
/// pixel: the means of the 8x8 pixels at the centre (where the caustic is) agree, |z| < 4 with
/// z = (A - B) / sqrt(var_A + var_B) of the region means; the whole images pass the default
/// comparison. The caustic must matter: the region is more than twice as bright as with
/// max_depth 2 (direct light only).
void expect_caustics_match_path_tracing(const std::function<std::string(bool, int)>& scene) {
  RenderResult on = render_ref(scene(true, 6), 256);
  RenderResult off = render_ref(scene(false, 6), 256);
  RenderResult direct = render_ref(scene(false, 2), 16);
  EXPECT_EQ(on.nonfinite, 0u);
  RegionMean a = region_mean(on, 12, 20, 8, 16), b = region_mean(off, 12, 20, 8, 16),
             d = region_mean(direct, 12, 20, 8, 16);
  const double z = (a.mean - b.mean) / std::sqrt(a.var + b.var);
  EXPECT_LT(std::abs(z), 4) << "caustics on " << a.mean << " +- " << std::sqrt(a.var) << ", off "
                            << b.mean << " +- " << std::sqrt(b.var);
  EXPECT_GT(a.mean, 2 * d.mean) << "direct light only: " << d.mean;
  lucent::CompareResult c = lucent::compare_images(on, off);
  EXPECT_TRUE(c.passed) << c.summary();
}

/// A glass ball (radius 0.5 at (0, 0, 1)) on a diffuse floor, seen from above at 45 degrees (the
/// image centre is the floor under the ball, beside the ball's image), with `more` shapes (a
/// lamp), and the floor's vertex normals `floor_normals` (JSON, or "" for none).
std::string glass_ball_scene(bool caustics, int max_depth, const std::string& more,
                             const std::string& floor_normals = "") {
  return std::string(R"({
    "camera": {"position": [0, -4, 4], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov": 12},
    "film": {"width": 32, "height": 24},
    "integrator": {"type": "path", "max_depth": )") +
         std::to_string(max_depth) + R"(, "caustics": )" + (caustics ? "true" : "false") + R"(},
    "materials": {"floor": {"type": "diffuse", "albedo": [0.7, 0.7, 0.7]},
                  "glass": {"type": "dielectric", "ior": 1.5},
                  "mirror": {"type": "mirror", "reflectance": [0.9, 0.9, 0.9]},
                  "lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [20, 20, 20]}},
    "shapes": [{"type": "triangles", "material": "floor",
                "positions": [[-10,-10,0],[10,-10,0],[10,10,0],[-10,10,0]],)" +
         (floor_normals.empty() ? "" : R"("normals": )" + floor_normals + ",") + R"(
                "indices": [0,1,2, 0,2,3]},
               {"type": "sphere", "center": [0, 0, 1], "radius": 0.5, "material": "glass"},
               )" +
         more + R"(]
  })";
}

// A render cancelled before it starts keeps nothing and says so: no light paths traced (N = 0
// divides nothing), every pixel empty, spp 0 (it said the 4 asked for).
TEST(ReferenceCaustics, CancelledBeforeStart) {
  lucent::Scene scene = lucent::test::scene_from(mirror_scene(true, R"({"type": "box"})"));
  std::atomic<bool> cancel{true};
  lucent::ReferenceOptions o;
  o.spp = 4;
  o.cancel = &cancel;
  RenderResult r = lucent::render_reference(scene, o);
  EXPECT_TRUE(r.cancelled);
  EXPECT_EQ(r.spp, 0u);
  EXPECT_EQ(r.nonfinite, 0u);
  for (size_t i = 0; i < r.samples.size(); ++i) {
    EXPECT_EQ(r.samples[i], 0u);
    EXPECT_EQ(r.mean.rgb[i * 3], 0.0f);
  }
}

// A small lamp over the ball: the ball focuses its light into a caustic on the floor below.
TEST(ReferenceCaustics, GlassBallCausticMatchesPathTracing) {
  expect_caustics_match_path_tracing([](bool caustics, int max_depth) {
    return glass_ball_scene(
        caustics, max_depth,
        R"({"type": "sphere", "center": [0, 0, 3], "radius": 0.25, "material": "lamp"})");
  });
}

// A lamp inside the ball: its light leaves the glass through one refraction, so the light
// tracer's adjoint weight (without the radiance weight's 1 / eta^2 = 2.25 here) is tested; every
// light on the floor is a caustic (shadow rays do not cross the glass).
TEST(ReferenceCaustics, LampInsideGlassMatchesPathTracing) {
  expect_caustics_match_path_tracing([](bool caustics, int max_depth) {
    return glass_ball_scene(
        caustics, max_depth,
        R"({"type": "sphere", "center": [0, 0, 1.1], "radius": 0.15, "material": "lamp"})");
  });
}

// Shading normals: the floor's vertex normals tilt by up to 17 degrees (the connection's
// |wl.ns| |wc.ng| / |wl.ng| and the camera's shading frame), and a mirror wall beside the ball
// whose vertex normals tilt by up to 11 degrees reflects the lamp onto the floor (the adjoint
// weight's shading-normal correction).
TEST(ReferenceCaustics, ShadingNormalsMatchPathTracing) {
  expect_caustics_match_path_tracing([](bool caustics, int max_depth) {
    return glass_ball_scene(
        caustics, max_depth,
        R"({"type": "sphere", "center": [0, 0, 3], "radius": 0.25, "material": "lamp"},
           {"type": "triangles", "material": "mirror",
            "positions": [[-1.2,-2,0],[-1.2,2,0],[-1.2,2,2.5],[-1.2,-2,2.5]],
            "normals": [[1,0.2,0],[1,-0.1,0.1],[1,0,-0.2],[1,0.1,0.15]],
            "indices": [0,2,1, 0,3,2]})",
        "[[0.3,0.1,1],[-0.2,0.3,1],[0.1,-0.3,1],[-0.3,-0.1,1]]");
  });
}

using lucent::test::bounced_caustic_scene;

// A point light: the wall is lit only through E N N S L (max_depth 4: camera, wall, floor,
// mirror, light), which path tracing cannot find with a point light: with caustics off the wall
// is exactly black; with caustics on (light path: mirror, floor, then a connection at the
// wall) it is lit, its mean over the whole image more than 10 of its standard errors above 0.
TEST(ReferenceCaustics, PointLightBouncedCaustic) {
  const std::string light =
      R"(], "lights": [{"type": "point", "position": [0, 0, 2.5], "intensity": [4, 4, 4]}])";
  RenderResult on = render_ref(bounced_caustic_scene(true, 4, light), 2048);
  RenderResult off = render_ref(bounced_caustic_scene(false, 4, light), 8);
  EXPECT_EQ(on.nonfinite, 0u);
  RegionMean a = region_mean(on, 0, 16, 0, 12), b = region_mean(off, 0, 16, 0, 12);
  EXPECT_GT(a.mean, 10 * std::sqrt(a.var)) << a.mean << " +- " << std::sqrt(a.var);
  EXPECT_EQ(b.mean, 0.0);
}

/// A sphere light (radius 0.45 at the point light's place) instead: path tracing alone finds
/// the light by BSDF sampling (e.g. wall, floor, mirror, lamp), so caustics on and off estimate
/// the same image; max_depth 6. Rendered at 2048 samples per pixel each, the means over the
/// whole image agree: |z| < 4 with z = (A - B) / sqrt(var_A + var_B) of the two means. It must
/// be lit: the caustics-off mean more than 10 of its standard errors. `more` adds shapes,
/// `camera` (when not empty) replaces the camera.
void expect_bounced_caustic_matches(const std::string& more = "", const std::string& camera = "") {
  const std::string light =
      R"(, {"type": "sphere", "center": [0, 0, 2.5], "radius": 0.45, "material": "lamp"}])";
  auto scene = [&](bool caustics) {
    return camera.empty() ? bounced_caustic_scene(caustics, 6, light, more)
                          : bounced_caustic_scene(caustics, 6, light, more, camera);
  };
  RenderResult on = render_ref(scene(true), samples(2048));
  RenderResult off = render_ref(scene(false), samples(2048));
  EXPECT_EQ(on.nonfinite, 0u);
  if (!kStatistics) return;
  RegionMean a = region_mean(on, 0, 16, 0, 12), b = region_mean(off, 0, 16, 0, 12);
  const double z = (a.mean - b.mean) / std::sqrt(a.var + b.var);
  EXPECT_LT(std::abs(z), 4) << "caustics on " << a.mean << " +- " << std::sqrt(a.var) << ", off "
                            << b.mean << " +- " << std::sqrt(b.var);
  EXPECT_GT(b.mean, 10 * std::sqrt(b.var)) << "the wall is lit";
}

// The wall of the scene above: with caustics on, the camera path leaves all of its light out
// (every path from the wall that reaches the lamp reads N+ S+), and light paths render it,
// connecting at the wall after the floor (E N N S L, and E N N N N S L: wall, floor, wall,
// floor, mirror).
TEST(ReferenceCaustics, SphereLightBouncedCausticMatchesPathTracing) {
  expect_bounced_caustic_matches();
}

// A caustic seen in mirrors (docs/rendering-model.md, "Caustics by light tracing"): the camera
// looks down at floor that the black square shades from the lamp and its image in the ceiling
// mirror, beside a vertical mirror wall (tests/support.hpp's kMirrorWall). Its light comes off
// the lit ring of the floor seen in the mirrors (floor, wall, ceiling mirror, lit floor, ceiling
// mirror, lamp: E N S S N S L), which light paths render (a non-delta lobe at the first hit, a
// delta one into the lamp); before 24 Nov 2026 a delta lobe after a non-delta one ended a light
// path and the camera path took these. Same comparison as above; it fails (z = -4.7) when only
// the camera path follows the rule.
TEST(ReferenceCaustics, SphereLightCausticSeenInAMirrorMatchesPathTracing) {
  expect_bounced_caustic_matches(lucent::test::kMirrorWall,
                                 lucent::test::kFloorBesideTheMirrorWall);
}

// The adjoint weight of a rough refraction (eta^2 = 2.25 entering): a frosted glass sheet
// z = 0.3 (rough dielectric, ior 1.5, roughness 0.3, front side up) covers the floor, and the
// camera at (4, 0, 1.8) looks down at it, at x within about 2.9 .. 5.1, in the mirror's light.
// The floor under the glass is lit by the mirror through the glass, and the camera sees that
// light through the glass: light paths mirror, glass (refracted, a non-delta lobe: the path
// goes on with the weight times eta^2), floor, glass from below (connected: E N N N S L). Same
// comparison as above (without the eta^2, z was -6.4 against 0.46 with it).
TEST(ReferenceCaustics, SphereLightCausticThroughFrostedGlassMatchesPathTracing) {
  expect_bounced_caustic_matches(
      R"(, {"type": "triangles", "material": "frosted",
            "positions": [[-6,-6,0.3],[6,-6,0.3],[6,6,0.3],[-6,6,0.3]],
            "indices": [0,1,2, 0,2,3]})",
      R"({"position": [4, 0, 1.8], "look_at": [4, 0, 0], "up": [0, 1, 0], "fov": 60})");
}

}  // namespace

namespace {

// The reference's variance counts a light path's connections that land in one pixel together:
// it sums the path's shares per pixel before squaring (render.cpp). The ensemble check of
// KernelCaustics.VarianceOfAPathsConnectionsInOnePixel (test_kernel_caustics.cpp) on the same
// scene: R = 400 renders (seeds 1000 ..), 2x2 film, tent radius 2, max_depth 6; the empirical
// over the reported variance of the pixel means must be 1 within 0.4 (relative sd of the ratio
// sqrt(2 / (R - 1)) = 0.071 for Gaussian means, so about 5 sd with room for heavier tails).
// Before the per-pixel sums: 5.3.
TEST(ReferenceCaustics, VarianceOfAPathsConnectionsInOnePixel) {
  lucent::Scene scene = lucent::test::scene_from(
      lucent::test::glass_lamp_box_scene(2, 2, R"({"type": "tent", "radius": 2})", 6));
  const int R = 400, spp = 16;
  lucent::ReferenceOptions o;
  o.spp = spp;
  o.threads = 1;
  const double ratio = lucent::test::ensemble_variance_ratio(
      [&](int k) {
        scene.integrator.seed = 1000u + static_cast<std::uint32_t>(k);
        return lucent::render_reference(scene, o);
      },
      R);
  EXPECT_NEAR(ratio, 1.0, 0.4) << "empirical over reported variance of the pixel means";
}

// KernelCaustics.ImageMeanZOfRendersDifferingInSamplesIsStandardNormal on the reference: the
// image-mean z of 300 seed pairs (8x8, gaussian radius 3, 4 spp, every pixel light-traced) has
// mean z^2 within 1 +- 0.5 (measured 1.00 +- 0.10 over 5 ensembles of 200 pairs; about 4 sd at
// 300). With the pixels taken as independent: about 8.
TEST(ReferenceCaustics, ImageMeanZOfRendersDifferingInSeedIsStandardNormal) {
  lucent::Scene scene = lucent::test::scene_from(
      lucent::test::glass_lamp_box_scene(8, 8, R"({"type": "gaussian", "radius": 3})", 6));
  lucent::ReferenceOptions o;
  o.spp = 4;
  o.threads = 1;
  const double z2 = lucent::test::mean_image_mean_z2(
      [&](int k) {
        scene.integrator.seed = 2000u + static_cast<std::uint32_t>(k);
        return lucent::render_reference(scene, o);
      },
      300);
  EXPECT_NEAR(z2, 1.0, 0.5) << "mean image-mean z^2 of 300 pairs";
}

}  // namespace

}  // namespace test_reference_caustics
