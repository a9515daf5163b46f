// End-to-end renders through the megakernel checked against closed-form answers. Every render
// compiles all kernel features (specialize = false), sharing one program with the other
// known-answer, stability and precision tests (see test_kernel_analytic.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "lucent/reference.hpp"
#include "support.hpp"

namespace test_render_analytic {

namespace {

using glm::dvec3;

// A diffuse plane (two triangles) seen straight on, lit by one point light off to the side.
// Radiance leaving the plane at x: L = albedo/pi * I * cos(theta) / r^2. With the box filter a
// pixel's value is the mean of L over its footprint, computed here by a 16x16 midpoint rule.
// Test: per-pixel z = |kernel - analytic| / sqrt(var / n) below 5 for every one of the 1024
// pixels (a Sidak-corrected two-sided test at alpha = 0.1% needs z > 4.9), and the relative
// error of the image mean below 0.3%.
TEST(RenderAnalytic, DiffusePlaneUnderPointLight) {
  const double albedo = 0.6, I = 50.0;
  const double lx = 0.7, ly = 0.4, lz = 2.0;  // light position; the plane is z = 0
  const char* scene = R"({
    "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 20},
    "film": {"width": 32, "height": 32},
    "integrator": {"type": "direct"},
    "materials": {"white": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]}},
    "shapes": [{"type": "triangles", "material": "white",
                "positions": [[-10,-10,0],[10,-10,0],[10,10,0],[-10,10,0]],
                "indices": [0,1,2, 0,2,3]}],
    "lights": [{"type": "point", "position": [0.7, 0.4, 2.0], "intensity": [50, 50, 50]}]
  })";
  const int spp = 64;
  lucent::RenderResult r = lucent::test::render_json(scene, spp, false);
  const double t = std::tan(10.0 * M_PI / 180.0);  // tan(fov / 2)
  auto radiance = [&](double fx, double fy) {      // film position in pixels
    // the camera ray through (fx, fy) meets z = 0 at 5 * ndc * tan(fov/2)
    double px = (2.0 * fx / 32 - 1) * t * 5.0, py = (1 - 2.0 * fy / 32) * t * 5.0;
    double dx = lx - px, dy = ly - py, dz = lz;
    double r2 = dx * dx + dy * dy + dz * dz;
    return albedo / M_PI * I * (dz / std::sqrt(r2)) / r2;
  };
  double worst_z = 0, sum_got = 0, sum_expected = 0;
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 32; ++x) {
      double expected = 0;
      for (int j = 0; j < 16; ++j)
        for (int i = 0; i < 16; ++i) expected += radiance(x + (i + 0.5) / 16, y + (j + 0.5) / 16);
      expected /= 256;
      double got = r.mean.pixel(x, y)[0];
      double se = std::sqrt(r.variance.pixel(x, y)[0] / spp) + 1e-6 * expected;
      worst_z = std::max(worst_z, std::abs(got - expected) / se);
      sum_got += got;
      sum_expected += expected;
    }
  }
  EXPECT_LT(worst_z, 5.0);
  EXPECT_LT(std::abs(sum_got - sum_expected) / sum_expected, 3e-3);
  EXPECT_EQ(r.nonfinite, 0u);
}

// The image mean of the plane z = 0 (albedo 0.6) seen by the camera of
// PointLightOverAHugeGroundSphere (at (0, 0, 5), fov 20) under a point light of intensity I at
// (0.7, 0.4, 2): the plane's radiance over the film, midpoint rule.
double plane_under_point_light_mean(double I) {
  const double albedo = 0.6, lx = 0.7, ly = 0.4, lz = 2.0;
  const double t = std::tan(10.0 * M_PI / 180.0);
  double expected = 0;
  for (int j = 0; j < 256; ++j)
    for (int i = 0; i < 256; ++i) {
      double px = (2.0 * (i + 0.5) / 256 - 1) * t * 5.0, py = (1 - 2.0 * (j + 0.5) / 256) * t * 5.0;
      double dx = lx - px, dy = ly - py, r2 = dx * dx + dy * dy + lz * lz;
      expected += albedo / M_PI * I * (lz / std::sqrt(r2)) / r2;
    }
  return expected / (256 * 256);
}

// The 32x32 render of `scene` at spp has the image mean `expected` (red) within 1%, and no
// non-finite sample.
void expect_image_mean(const std::string& scene, int spp, double expected,
                       const std::string& what) {
  lucent::RenderResult r = lucent::test::render_json(scene, spp, false);
  double sum = 0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) sum += r.mean.pixel(x, y)[0];
  EXPECT_NEAR(sum / 1024 / expected, 1.0, 0.01) << what;
  EXPECT_EQ(r.nonfinite, 0u) << what;
}

// The plane above, but the top of a huge ground sphere (smallpt's walls are spheres of radius
// 1e5), rendered by the path integrator. Float knows points of such a sphere only to about its
// ulp (0.008 at 1e5), and the shadow ray's origin is pushed off the surface by 8 times that
// error bound: 0.3 at radius 1e5, 3 at 1e6. The path integrator measured a point light's
// distance and direction from that origin, so this image came out 32% too bright, and black at
// radius 1e6 (the origin above the light). Measured from the surface point, it is the plane's
// image to float's precision there: each pixel's radiance moves by up to about 1% with its
// point's error, so the test is the image mean within 1% of the analytic one.
TEST(RenderAnalytic, PointLightOverAHugeGroundSphere) {
  const double expected = plane_under_point_light_mean(50.0);
  for (const char* radius : {"1e5", "1e6"}) {
    const std::string scene = std::string(R"({
      "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 20},
      "film": {"width": 32, "height": 32},
      "integrator": {"type": "path", "max_depth": 2},
      "materials": {"white": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]}},
      "shapes": [{"type": "sphere", "center": [0, 0, -)") +
                              radius + R"(], "radius": )" + radius + R"(, "material": "white"}],
      "lights": [{"type": "point", "position": [0.7, 0.4, 2.0], "intensity": [50, 50, 50]}]
    })";
    expect_image_mean(scene, 16, expected, std::string("radius ") + radius);
  }
}

// The same ground spheres under a sphere lamp (radius 0.1 at the point light's position, radiance
// 100: the point light's limit with I = pi r^2 L = pi). Sampled from the shadow ray's origin, 0.3
// above the floor at radius 1e5, the lamp lit the floor 25% too brightly, twice as brightly at
// 3e5, and not at all at 1e6 (the origin above the lamp's centre). Sampled from the
// surface point, a shadow ray from that origin to a point near the lamp's silhouette could enter
// the lamp first and be shadowed by it: 1.6% too dark at radius 3e5 and 73% at 1e6 (the origin
// above the lamp). The shadow ray now stops where it meets the lamp (light/sphere.cl). The image
// mean is the plane's within 1%, as for the point light; the closed form is the point light's
// (a sphere fully above the horizon lights a plane as a point of the same intensity).
TEST(RenderAnalytic, SphereLightOverAHugeGroundSphere) {
  const double expected = plane_under_point_light_mean(M_PI);
  for (const char* radius : {"1e5", "3e5", "1e6"}) {
    const std::string scene = std::string(R"({
      "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 20},
      "film": {"width": 32, "height": 32},
      "integrator": {"type": "path", "max_depth": 2},
      "materials": {"white": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]},
                    "lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [100, 100, 100]}},
      "shapes": [{"type": "sphere", "center": [0.7, 0.4, 2], "radius": 0.1, "material": "lamp"},
                 {"type": "sphere", "center": [0, 0, -)") +
                              radius + R"(], "radius": )" + radius + R"(, "material": "white"}]
    })";
    expect_image_mean(scene, 64, expected, std::string("radius ") + radius);
  }
}

// A sphere lit head-on: the pixel at the centre of the image sees the point of the sphere
// nearest the camera and light, where cos(theta) = 1 and r = distance - radius.
TEST(RenderAnalytic, SphereFacingPointLight) {
  const char* scene = R"({
    "camera": {"position": [0, 0, 10], "look_at": [0, 0, 0], "fov": 2},
    "film": {"width": 9, "height": 9},
    "integrator": {"type": "direct"},
    "materials": {"m": {"type": "diffuse", "albedo": [0.5, 0.25, 1.0]}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}],
    "lights": [{"type": "point", "position": [0, 0, 10], "intensity": [81, 81, 81]}]
  })";
  lucent::RenderResult r = lucent::test::render_json(scene, 16, false);
  const float* c = r.mean.pixel(4, 4);
  const double E = 81.0 / 81.0;  // I cos / r^2 with r = 9
  EXPECT_NEAR(c[0], 0.5 / M_PI * E, 1e-3 * 0.5 / M_PI * E * 10);
  EXPECT_NEAR(c[1], 0.25 / M_PI * E, 1e-2 * 0.25 / M_PI * E);
  EXPECT_NEAR(c[2], 1.0 / M_PI * E, 1e-2 * 1.0 / M_PI * E);
}

// Shadow rays stop at the light: an occluder beyond the light (seen from the plane) does not
// shadow the plane.
TEST(RenderAnalytic, ShadowRaysAreBoundedByTheLightDistance) {
  // the camera looks at the origin from off-axis, past the sphere that sits above the light
  const char* scene2 = R"({
    "camera": {"position": [3, 0, 5], "look_at": [0, 0, 0], "fov": 3},
    "film": {"width": 8, "height": 8},
    "integrator": {"type": "direct"},
    "materials": {"w": {"type": "diffuse", "albedo": [1, 1, 1]}},
    "shapes": [
      {"type": "triangles", "material": "w", "positions": [[-5,-5,0],[5,-5,0],[5,5,0],[-5,5,0]],
       "indices": [0,1,2, 0,2,3]},
      {"type": "sphere", "center": [0, 0, 3], "radius": 0.5, "material": "w"}
    ],
    "lights": [{"type": "point", "position": [0, 0, 1], "intensity": [1, 1, 1]}]
  })";
  lucent::RenderResult r = lucent::test::render_json(scene2, 4, false);
  const float* c = r.mean.pixel(4, 4);
  // the pixel sees (about) the origin: E = 1 * 1 / 1, L = 1/pi
  EXPECT_NEAR(c[0], 1.0 / M_PI, 0.02 / M_PI);
}

// A point light 0.003 under an opaque floor lights nothing above it: a sphere 20 above is black
// in every integrator. The path integrator's shadow rays stopped 2e-4 of their length short of
// the light (a margin for an area light's own surface, which a point light has not), so the floor
// did not hide this light from the sphere: mean 0.007 instead of 0.
TEST(RenderAnalytic, PointLightJustUnderAFloorLightsNothingAboveIt) {
  for (const char* integrator : {"path", "direct", "whitted"}) {
    const std::string scene = std::string(R"({
      "camera": {"position": [0, 25, 10], "look_at": [0, 20, 0], "fov": 40},
      "film": {"width": 16, "height": 16},
      "integrator": {"type": ")") +
                              integrator + R"(", "max_depth": 4},
      "materials": {"white": {"type": "diffuse", "albedo": [0.7, 0.7, 0.7]}},
      "shapes": [
        {"type": "triangles", "material": "white", "indices": [0,2,1, 0,3,2],
         "positions": [[-100,0,-100],[100,0,-100],[100,0,100],[-100,0,100]]},
        {"type": "sphere", "center": [0, 20, 0], "radius": 3, "material": "white"}],
      "lights": [{"type": "point", "position": [0, -0.003, 0], "intensity": [1000, 1000, 1000]}]
    })";
    lucent::RenderResult r = lucent::test::render_json(scene, 4, false);
    double brightest = 0;
    for (float v : r.mean.rgb) brightest = std::max(brightest, double(v));
    EXPECT_EQ(brightest, 0.0) << integrator;
  }
}

// An emitter never lights its own surface: every pixel well inside an emissive rough glass
// sphere, alone in the dark, is its emission exactly (seen directly; its light reaches its inside
// only through its back faces, which do not emit). Next-event estimation sampled the sphere from
// the origin just outside it, a cone of almost a hemisphere, and the shadow ray behind the glass
// reached those points from inside: a bright ring up to 1.249 (image mean 4% high, z = 84
// against the reference).
TEST(RenderAnalytic, EmissiveRoughGlassSphereDoesNotLightItself) {
  for (int depth : {2, 8}) {
    const std::string scene = R"({
      "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0], "fov": 30},
      "film": {"width": 24, "height": 24},
      "integrator": {"type": "path", "max_depth": )" +
                              std::to_string(depth) + R"(},
      "materials": {"e": {"type": "rough_dielectric", "ior": 1.3, "roughness": 0.4,
                          "emission": [1, 1, 1]}},
      "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "e"}]
    })";
    lucent::RenderResult r = lucent::test::render_json(scene, 16, false);
    int inside = 0;
    for (int y = 0; y < 24; ++y)
      for (int x = 0; x < 24; ++x) {
        // the silhouette's radius is 0.964 of the half height; pixels within 0.8 of it are
        // wholly inside
        if (std::hypot(x + 0.5 - 12, y + 0.5 - 12) > 0.8 * 12) continue;
        ++inside;
        for (int c = 0; c < 3; ++c)
          ASSERT_EQ(r.mean.pixel(x, y)[c], 1.0f)
              << "depth " << depth << ", pixel " << x << "," << y;
      }
    EXPECT_GT(inside, 250);
  }
}

// A sphere light so small or far that its cone's pdf exceeds 1.8e19 (radius 1e-11 at distance
// 1: a star, a far sun) lights a plane as its point-light limit, 0.5 L (r/d)^2 under it. The
// power heuristic squared that pdf in float: inf / inf made nearly every lit sample NaN (14,333
// of 16,384 in a reviewer's scene), and the lit pixels kept no samples at all.
TEST(RenderAnalytic, TinySphereLightLightsAsItsPointLimit) {
  const char* scene = R"({
    "camera": {"position": [0, 0.5, 0.0], "look_at": [0, 0, 0], "up": [0, 0, -1], "fov": 1},
    "film": {"width": 1, "height": 1},
    "integrator": {"type": "path", "max_depth": 2, "sampler": "independent"},
    "materials": {"m": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]},
                  "lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [1e20, 1e20, 1e20]}},
    "shapes": [{"type": "triangles", "material": "m", "indices": [0,2,1, 0,3,2],
                "positions": [[-3,0,-3],[3,0,-3],[3,0,3],[-3,0,3]]},
               {"type": "sphere", "center": [0, 1, 0], "radius": 1e-11, "material": "lamp"}]
  })";
  lucent::RenderResult r = lucent::test::render_json(scene, 64, false);
  EXPECT_EQ(r.nonfinite, 0u);
  // 0.5 / pi x pi L sin^2 (alpha) cos: the pixel sees the plane within 0.0044 of the point under
  // the light (cos and distance within 2e-5 of 1)
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(r.mean.pixel(0, 0)[c], 5e-3, 5e-3 * 1e-3) << c;
}

// Irradiance at p (normal +y) from a polygon of radiance L (Lambert's formula: half the sum over
// the edges of the angle they subtend times the cosine of their plane's normal with +y).
double polygon_irradiance(dvec3 p, const std::vector<dvec3>& verts, double L) {
  double sum = 0;
  for (size_t i = 0; i < verts.size(); ++i) {
    dvec3 a = glm::normalize(verts[i] - p), b = glm::normalize(verts[(i + 1) % verts.size()] - p);
    dvec3 c = glm::cross(a, b);
    sum += std::atan2(glm::length(c), glm::dot(a, b)) * glm::normalize(c).y;
  }
  return std::abs(0.5 * L * sum);
}

// Small lamps just above a floor of +-60, each seen by a pixel (1e-5 or less across) at the
// floor's point under it: the floor's radiance there is albedo / pi times the closed-form
// irradiance, pi L sin^2(theta_max) for a sphere of angular radius theta_max straight above,
// Lambert's polygon formula for a square. Float pushes rays off the floor by its rounding at 60
// (about 3e-5), and each case failed in float (double was right):
// - a sphere of radius 0.003 and a square of side 0.001, both 0.01 up: +1.0% while lights were
//   sampled from the pushed origin (the floor lit as the point that far above it);
// - a square of side 0.006 at 0.003 (+1.4%) and one of 0.02 at 1e-4 (+0.5%): sampled from the
//   floor's point, BSDF hits were MIS-weighted with the light's pdf at the distance from the
//   pushed origin, so the two strategies' weights did not sum to 1;
// - a sphere of radius 0.01 whose bottom is 3e-5 up (-57%) and a square of side 2e-4 at 2e-5
//   (-83%): the pushed origin lies inside the sphere or above the square, where BSDF-sampled
//   rays never reach their emitting side, but MIS still gave those rays their share.
// Tolerances: a fifth of the old error or less, and 4-8 times the scatter of Sobol's estimate
// over seeds at these spp (the last case, sampled by area under a lamp 10 times wider than
// high, scatters by 3%).
TEST(RenderAnalytic, AreaLightsLightTheSurfacePoint) {
  const double albedo = 0.5;
  auto square = [](double side, double h) {
    const double a = side / 2;
    return std::vector<dvec3>{{-a, h, -a}, {a, h, -a}, {a, h, a}, {-a, h, a}};
  };
  auto square_json = [](const std::vector<dvec3>& v) {
    // facing down: (v1 - v0) x (v2 - v0) along -y for the triangles (0, 1, 2) and (0, 2, 3)
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  R"({"type": "triangles", "material": "lamp", "indices": [0,1,2, 0,2,3],
                      "positions": [[%.17g,%.17g,%.17g],[%.17g,%.17g,%.17g],[%.17g,%.17g,%.17g],
                                    [%.17g,%.17g,%.17g]]})",
                  v[0].x, v[0].y, v[0].z, v[1].x, v[1].y, v[1].z, v[2].x, v[2].y, v[2].z, v[3].x,
                  v[3].y, v[3].z);
    return std::string(buf);
  };
  auto square_lamp = [&](double side, double h) {
    return std::make_pair(square_json(square(side, h)),
                          albedo / M_PI * polygon_irradiance(dvec3(0), square(side, h), 1.0));
  };
  auto sphere_lamp = [&](double r, double centre) {
    char buf[256];
    std::snprintf(
        buf, sizeof buf,
        R"({"type": "sphere", "center": [0, %.17g, 0], "radius": %.17g, "material": "lamp"})",
        centre, r);
    return std::make_pair(std::string(buf), albedo * (r / centre) * (r / centre));
  };
  struct Case {
    std::string name;
    std::pair<std::string, double> lamp;  // its shape, the expected radiance
    dvec3 camera;
    double fov;
    int spp;
    double tolerance;
  };
  // the first two: the camera 0.02 from the point at 36 degrees of elevation
  const dvec3 at36 = 0.02 * dvec3(0.6 * std::cos(0.635), std::sin(0.635), 0.8 * std::cos(0.635));
  const double fov36 = 2 * std::atan(0.5e-5 / 0.02) * 180 / M_PI;
  const Case cases[] = {
      {"sphere 0.003 at 0.01", sphere_lamp(0.01 * std::sin(0.3), 0.01), at36, fov36, 4096, 2e-3},
      {"square 0.001 at 0.01", square_lamp(0.001, 0.01), at36, fov36, 4096, 2e-3},
      {"square 0.006 at 0.003",
       square_lamp(0.006, 0.003),
       {0.02866, 0.014776, 0.038213},
       0.0115,
       65536,
       5e-3},
      {"square 0.02 at 1e-4", square_lamp(0.02, 1e-4), {0.001, 5e-5, 0.001}, 0.001, 16384, 2e-3},
      {"sphere 0.01, 3e-5 above",
       sphere_lamp(0.01, 0.01003),
       {0.001, 1.5e-5, 0.001},
       0.001,
       16384,
       1e-2},
      {"square 2e-4 at 2e-5", square_lamp(2e-4, 2e-5), {1e-4, 5e-6, 1e-4}, 0.001, 65536, 0.12},
  };
  for (const Case& c : cases) {
    char camera[256];
    std::snprintf(camera, sizeof camera,
                  R"("camera": {"position": [%.17g, %.17g, %.17g], "look_at": [0, 0, 0],
                                "up": [0, 1, 0], "fov": %.17g})",
                  c.camera.x, c.camera.y, c.camera.z, c.fov);
    const std::string scene = std::string("{") + camera + R"(,
      "film": {"width": 1, "height": 1},
      "integrator": {"type": "path", "max_depth": 2},
      "materials": {"floor": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]},
                    "lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [1, 1, 1]}},
      "shapes": [{"type": "triangles", "material": "floor", "indices": [0,1,2, 0,2,3],
                  "positions": [[-60,0,-60],[-60,0,60],[60,0,60],[60,0,-60]]}, )" +
                              c.lamp.first + "]}";
    lucent::RenderResult res = lucent::test::render_json(scene, c.spp, false);
    EXPECT_EQ(res.nonfinite, 0u) << c.name;
    EXPECT_NEAR(res.mean.pixel(0, 0)[1] / c.lamp.second, 1.0, c.tolerance) << c.name;
  }
}

// Bright samples are kept while their own square fits in a float (1.8e19): a pass's sum of
// squares, in double, cannot overflow. Judged by the pass's float sum, a pixel half covered by a
// lamp of 1e18 lost the bright samples that came after the first few hundred of a pass, and kept
// the dark ones: a reviewer's lamp of 1e17 rendered 4.4% dark (z -90). Here the pixel's share of
// the lamp is the disk's share of the image plane, pi tan^2(asin(0.2)) / (2 tan 15 deg)^2.
TEST(RenderAnalytic, BrightSamplesAreKeptWhileTheirSquareFitsAFloat) {
  const char* scene = R"({
    "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0], "fov": 30},
    "film": {"width": 1, "height": 1},
    "integrator": {"type": "path", "max_depth": 1, "sampler": "independent"},
    "materials": {"lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [1e18, 1e18, 1e18]}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 0.8, "material": "lamp"}]
  })";
  const int spp = 16384;
  lucent::RenderResult r = lucent::test::render_json(scene, spp, false);
  EXPECT_EQ(r.nonfinite, 0u);
  const double R = std::tan(std::asin(0.2)), half = std::tan(15.0 * M_PI / 180.0);
  const double p = M_PI * R * R / (4 * half * half);  // 0.4558
  const double sigma = std::sqrt(p * (1 - p) / spp);  // binomial: 0.0039
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(r.mean.pixel(0, 0)[c] / 1e18, p, 5 * sigma) << c;
  // beyond it (1e20), kernel and reference both count the lamp's samples as non-finite and keep
  // the dark ones: the reference summed them, wrote an infinite variance, and compare refused
  // its file
  std::string brighter = scene;
  brighter.replace(brighter.find("1e18, 1e18, 1e18"), 16, "1e20, 1e20, 1e20");
  lucent::ReferenceOptions ro;
  ro.spp = 256;
  for (const lucent::RenderResult& b :
       {lucent::test::render_json(brighter, 256, false),
        lucent::render_reference(lucent::parse_scene(brighter, "b.json"), ro)}) {
    EXPECT_GT(b.nonfinite, 256 / 4);
    EXPECT_LT(b.nonfinite, 3 * 256 / 4);
    EXPECT_EQ(b.mean.pixel(0, 0)[0], 0.0f);
    for (float v : b.variance.rgb) EXPECT_TRUE(std::isfinite(v));
  }
}

/// The brightest pixel of a floor under `lamp` (a shape of material "lamp", whose lowest point is
/// at height 2), with an opaque white quad of half-width `cover` at 1.9999 between them: 0 when the
/// cover hides the lamp (16x16, `spp` samples, max_depth 4).
double brightest_under_a_covered_lamp(const std::string& lamp, double cover, int spp) {
  const std::string c = std::to_string(cover);
  const std::string scene = R"({
    "camera": {"position": [0, 1, 4], "look_at": [0, 0.5, 0], "fov": 45},
    "film": {"width": 16, "height": 16},
    "integrator": {"type": "path", "max_depth": 4},
    "materials": {"white": {"type": "diffuse", "albedo": [0.7, 0.7, 0.7]},
                  "lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [10, 10, 10]}},
    "shapes": [
      {"type": "triangles", "material": "white", "indices": [0,2,1, 0,3,2],
       "positions": [[-5,0,-5],[5,0,-5],[5,0,5],[-5,0,5]]},
      )" + lamp + R"(,
      {"type": "triangles", "material": "white", "indices": [0,1,2, 0,2,3],
       "positions": [[-)" + c +
                            ",1.9999,-" + c + "],[" + c + ",1.9999,-" + c + "],[" + c + ",1.9999," +
                            c + "],[-" + c + ",1.9999," + c + R"(]]}]
  })";
  lucent::RenderResult r = lucent::test::render_json(scene, spp, false);
  double brightest = 0;
  for (float v : r.mean.rgb) brightest = std::max(brightest, double(v));
  return brightest;
}

// The same for an emitting quad with an opaque quad 1e-4 under it: the floor below is black.
// Shadow rays towards every light's surface stopped 2e-4 of their length short of it, so the
// cover, 1e-4 / 2 of the distance in front of the lamp, let its light through (mean 0.49). A
// triangle light now bounds that margin by its own rounding (light/triangle.cl).
TEST(RenderAnalytic, CoverJustUnderAnEmittingQuadHidesIt) {
  EXPECT_EQ(brightest_under_a_covered_lamp(R"({"type": "triangles", "material": "lamp",
       "indices": [0,1,2, 0,2,3], "positions": [[-1,2,-1],[1,2,-1],[1,2,1],[-1,2,1]]})",
                                           2, 8),
            0.0);
}

// The same for a sphere light: a lamp of radius 10 whose lowest point is 1e-4 above an opaque
// quad. Its shadow rays stopped max(2e-4 of their length, 4 ulps of the sphere) short of it, so
// the sampled points within ~5e-4 of the cover (a disk of 0.1 under the lamp) were seen through
// it (mean 0.0019); a smallpt-style lamp of radius 600 poking 0.27 through a ceiling 80 above the
// floor showed 0.016 more of itself, +0.8% on the room's image. A sphere light now bounds that
// margin by its own rounding along the ray, as a triangle light does (light/sphere.cl).
TEST(RenderAnalytic, CoverJustUnderASphereLightHidesIt) {
  EXPECT_EQ(
      brightest_under_a_covered_lamp(
          R"({"type": "sphere", "center": [0, 12, 0], "radius": 10, "material": "lamp"})", 40, 64),
      0.0);
}

// A diffuse floor (albedo 0.5) under a sky of radiance 1, whose map also holds a 3x3 sun of 1e12
// below the horizon: the floor's radiance is 0.5 x 1 exactly, with or without MIS. The sun takes
// the whole texel CDF (the sky's 32,000 texels together hold 0.06 of a lattice step), so light
// sampling never picks a sky texel, and picks the sun, which lights nothing. Every sample is then
// BSDF sampling's: a cosine-sampled direction that sees the sky, 0.5 x 1 whatever the direction,
// so each pixel is 0.5 up to float rounding. Without MIS, the path tracer gave escaped rays weight
// 0 and lost the sky (docs/rendering-model.md: such directions are BSDF sampling's). (A sun of
// 1e7 left some sky texels a lattice step, whose rare picks made the image mean vary by 20%
// from seed to seed.)
TEST(RenderAnalytic, SkyTexelsLightSamplingNeverPicksAreLitWithoutMis) {
  const std::string dir = lucent::test::temp_dir();
  const int w = 256, h = 128;
  lucent::Image sky{w, h, std::vector<float>(size_t(w) * h * 3, 1.0f)};
  for (int y = 100; y < 103; ++y)
    for (int x = 100; x < 103; ++x)
      for (int c = 0; c < 3; ++c) sky.pixel(x, y)[c] = 1e12f;
  lucent::write_image(dir + "/sky.pfm", sky);
  for (const char* mis : {"true", "false"}) {
    const std::string scene = R"({
      "camera": {"position": [0, 5, 0.001], "look_at": [0, 0, 0], "up": [0, 0, -1], "fov": 20},
      "film": {"width": 16, "height": 16, "filter": {"type": "box", "radius": 0.5}},
      "integrator": {"type": "path", "max_depth": 2, "sampler": "independent", "mis": )" +
                              std::string(mis) + R"(},
      "materials": {"floor": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
      "shapes": [{"type": "triangles", "material": "floor",
                  "positions": [[-20, 0, -20], [20, 0, -20], [20, 0, 20], [-20, 0, 20]],
                  "indices": [0, 2, 1, 0, 3, 2]}],
      "lights": [{"type": "environment", "file": ")" +
                              dir + R"(/sky.pfm"}]})";
    lucent::RenderResult r = lucent::test::render_json(scene, 16, false);
    for (size_t i = 0; i < r.mean.rgb.size(); ++i)
      ASSERT_NEAR(r.mean.rgb[i], 0.5, 1e-4) << "mis " << mis << ", value " << i;
  }
}

}  // namespace

}  // namespace test_render_analytic
