// The reference integrator (src/reference/) checked against closed-form answers. Statistical
// checks use lucent::compare_images against a deterministic expected image: per pixel-channel
// z = (render - expected) / sqrt(var / n + eps^2), Sidak-corrected two-sided test at family-wise
// alpha = 0.01 (|z| < ~4.65 for 32x32 pixels), 99.5% of the pixels required to pass (the sample
// variance of heavy-tailed estimators can be underestimated in a few pixels), plus the test of
// the image mean per channel (|z| < 2.93), which catches a bias of a fraction of a percent. Each
// test states any further tolerance.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

#include "lucent/compare.hpp"
#include "lucent/reference.hpp"
#include "reference/bsdf/bsdf.hpp"
#include "reference/bsdf/parts.hpp"
#include "support.hpp"

namespace test_reference_analytic {

namespace {

using lucent::RenderResult;

RenderResult render_ref(const std::string& json, int spp) {
  lucent::Scene scene = lucent::test::scene_from(json);
  lucent::ReferenceOptions o;
  o.spp = spp;
  return lucent::render_reference(scene, o);
}

/// A deterministic image of the same size whose pixel (x, y) is f(x, y).
RenderResult expected_image(const RenderResult& like,
                            const std::function<glm::dvec3(int, int)>& f) {
  RenderResult e;
  e.mean = like.mean;
  for (int y = 0; y < like.mean.height; ++y)
    for (int x = 0; x < like.mean.width; ++x) {
      glm::dvec3 v = f(x, y);
      for (int c = 0; c < 3; ++c) e.mean.pixel(x, y)[c] = static_cast<float>(v[c]);
    }
  return e;
}

/// The default comparison: 99.5% of the pixels pass and the image means agree.
void expect_matches(const RenderResult& got, const RenderResult& expected) {
  lucent::CompareResult c = lucent::compare_images(got, expected);
  EXPECT_TRUE(c.passed) << c.summary();
  EXPECT_EQ(got.nonfinite, 0u);
}

// A sphere resting on a floor under a point light, the floor one triangle that reaches 10 or
// 1e9 from the origin: the same view, so the same image (the same samples: a compare at family-
// wise alpha 0.01 with the images' own variances). The reference pushed its spawned rays off a
// surface by 1e-9 of the primitive's coordinates, an offset of 1 on the 1e9 floor: the
// sphere's contact shadow vanished (max |z| 1711).
TEST(ReferenceAnalytic, LargeFloorKeepsTheContactShadow) {
  RenderResult images[2];
  for (int k = 0; k < 2; ++k) {
    const std::string size = k == 0 ? "10" : "1e9";
    images[k] = render_ref(R"({
      "camera": {"position": [0, 3, 0.5], "look_at": [0, 0, 0], "fov": 60},
      "film": {"width": 32, "height": 32},
      "integrator": {"type": "path", "max_depth": 3, "seed": 5},
      "materials": {"white": {"type": "diffuse", "albedo": [0.7, 0.7, 0.7]}},
      "shapes": [{"type": "triangles", "material": "white", "indices": [0, 2, 1],
                  "positions": [[-)" +
                               size + ", 0, -" + size + "], [" + size + ", 0, -" + size +
                               "], [0, 0, " + size + R"(]]},
                 {"type": "sphere", "center": [0, 0.3, 0], "radius": 0.3, "material": "white"}],
      "lights": [{"type": "point", "position": [0.5, 2, 0.2], "intensity": [5, 5, 5]}]
    })",
                           64);
  }
  lucent::CompareResult c = lucent::compare_images(images[1], images[0]);
  EXPECT_TRUE(c.passed) << c.summary();
}

// White furnace: every surface reflects all it receives (diffuse albedo 1, mirror reflectance 1,
// clear glass), lit by a uniform environment L: the constant L solves the rendering equation, so
// every pixel's expected value is L, at unbounded depth (max_depth 10000, Russian roulette).
TEST(ReferenceAnalytic, WhiteFurnace) {
  const char* scene = R"({
    "camera": {"position": [0, 1, 6], "look_at": [0, 0.3, 0], "fov": 40},
    "film": {"width": 32, "height": 32},
    "integrator": {"type": "path", "max_depth": 10000, "rr_depth": 3},
    "materials": {"white": {"type": "diffuse", "albedo": [1, 1, 1]},
                  "mirror": {"type": "mirror"},
                  "glass": {"type": "dielectric", "ior": 1.5}},
    "shapes": [
      {"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "white"},
      {"type": "sphere", "center": [1.6, 0.2, 0.3], "radius": 0.7, "material": "glass"},
      {"type": "sphere", "center": [-1.5, 0.3, 0.2], "radius": 0.6, "material": "mirror"},
      {"type": "triangles", "material": "white",
       "positions": [[-4,-1,-4],[4,-1,-4],[4,-1,4],[-4,-1,4]], "indices": [0,2,1, 0,3,2]}],
    "lights": [{"type": "environment", "radiance": [0.5, 0.75, 1.0]}]
  })";
  RenderResult r = render_ref(scene, 64);
  expect_matches(r, expected_image(r, [](int, int) { return glm::dvec3(0.5, 0.75, 1.0); }));
}

// Point light over a diffuse plane z = 0, camera straight above: L = albedo / pi * I cos / r^2.
// A box filter of radius 1e-4 pixel makes each pixel the radiance at its centre (the
// difference is below 1e-5 relative); direct and path (max_depth 2) must both give it: relative
// error below 1e-4 everywhere.
TEST(ReferenceAnalytic, PointLightOverPlane) {
  const double albedo = 0.6, I = 50, lx = 0.7, ly = 0.4, lz = 2.0;
  for (const char* integrator : {"direct", "path"}) {
    std::string scene = std::string(R"({
      "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 20},
      "film": {"width": 24, "height": 16, "filter": {"type": "box", "radius": 0.0001}},
      "integrator": {"type": ")") +
                        integrator + R"(", "max_depth": 2},
      "materials": {"white": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]}},
      "shapes": [{"type": "triangles", "material": "white",
                  "positions": [[-10,-10,0],[10,-10,0],[10,10,0],[-10,10,0]],
                  "indices": [0,1,2, 0,2,3]}],
      "lights": [{"type": "point", "position": [0.7, 0.4, 2.0], "intensity": [50, 50, 50]}]
    })";
    RenderResult r = render_ref(scene, 4);
    const double t = std::tan(10.0 * M_PI / 180.0);
    double worst = 0;
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 24; ++x) {
        double px = (2.0 * (x + 0.5) / 24 - 1) * t * 1.5 * 5.0,
               py = (1 - 2.0 * (y + 0.5) / 16) * t * 5.0;
        double dx = lx - px, dy = ly - py, r2 = dx * dx + dy * dy + lz * lz;
        double expected = albedo / M_PI * I * (lz / std::sqrt(r2)) / r2;
        worst = std::max(worst, std::abs(r.mean.pixel(x, y)[1] - expected) / expected);
      }
    EXPECT_LT(worst, 1e-4) << integrator;
  }
}

// A spherical emitter (radius R, radiance Le, centre c) fully above the tangent plane of a
// diffuse surface point p with normal n gives E = pi Le R^2 cos(theta) / D^2, D = |c - p|,
// cos(theta) = n . (c - p) / D (pi Le (R/d)^2 right below it). The camera sees a small patch
// around the origin with a tiny box filter, so a pixel's expected value is albedo / pi * E at
// its centre; path tracing with max_depth 2 (direct light only: light sampling and BSDF sampling
// with MIS). The floor is a plane, then a sphere of radius 1000 tangent to it at the origin (large
// primitives need large ray offsets, which must not make the light hide itself).
TEST(ReferenceAnalytic, SphericalEmitterIrradiance) {
  const double albedo = 0.5, Le = 3, R = 0.5;
  const glm::dvec3 c(0, 0, 2);
  for (bool sphere_floor : {false, true}) {
    SCOPED_TRACE(sphere_floor ? "sphere floor" : "plane floor");
    std::string floor =
        sphere_floor
            ? R"({"type": "sphere", "center": [0, 0, -1000], "radius": 1000, "material": "white"})"
            : R"({"type": "triangles", "material": "white",
                                  "positions": [[-10,-10,0],[10,-10,0],[10,10,0],[-10,10,0]],
                                  "indices": [0,1,2, 0,2,3]})";
    std::string scene = R"({
      "camera": {"position": [2, 0, 2], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov": 10},
      "film": {"width": 32, "height": 32, "filter": {"type": "box", "radius": 0.0001}},
      "integrator": {"type": "path", "max_depth": 2},
      "materials": {"white": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]},
                    "lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [3, 3, 3]}},
      "shapes": [)" + floor +
                        R"(,
                 {"type": "sphere", "center": [0, 0, 2], "radius": 0.5, "material": "lamp"}]
    })";
    RenderResult r = render_ref(scene, 64);
    // the camera basis, as the model defines it, to find where each pixel centre meets the floor
    glm::dvec3 pos(2, 0, 2), fwd = glm::normalize(-pos),
                             right = glm::normalize(glm::cross(fwd, {0, 0, 1}));
    glm::dvec3 up = glm::cross(right, fwd);
    const double t = std::tan(5.0 * M_PI / 180.0);
    RenderResult e = expected_image(r, [&](int x, int y) {
      double nx = (2.0 * (x + 0.5) / 32 - 1) * t, ny = (1 - 2.0 * (y + 0.5) / 32) * t;
      glm::dvec3 dir = glm::normalize(fwd + nx * right + ny * up), p, n(0, 0, 1);
      if (sphere_floor) {
        glm::dvec3 f = pos - glm::dvec3(0, 0, -1000);
        double b = glm::dot(f, dir), cc = glm::dot(f, f) - 1e6;
        p = pos + (-b - std::sqrt(b * b - cc)) * dir;
        n = glm::normalize(p - glm::dvec3(0, 0, -1000));
      } else {
        p = pos + (-pos.z / dir.z) * dir;
      }
      glm::dvec3 to = c - p;
      double D = glm::length(to);
      double E = M_PI * Le * R * R * (glm::dot(n, to) / D) / (D * D);
      return glm::dvec3(albedo / M_PI * E);
    });
    expect_matches(r, e);
  }
}

// A closed cube whose inward-facing walls (triangle fronts) all have albedo rho and emission Le:
// the radiance everywhere inside is Le / (1 - rho) at unbounded depth, and
// Le (1 - rho^k) / (1 - rho) with max_depth k (k segments: k - 1 bounces).
TEST(ReferenceAnalytic, ClosedEmissiveBox) {
  auto scene = [](int max_depth) {
    return std::string(R"({
      "camera": {"position": [0.1, -0.2, 0.3], "look_at": [1, 0.5, -0.2], "fov": 100},
      "film": {"width": 24, "height": 24},
      "integrator": {"type": "path", "rr_depth": 2, "max_depth": )") +
           std::to_string(max_depth) + R"(},
      "materials": {"wall": {"type": "diffuse", "albedo": [0.5, 0.25, 0.75], "emission": [1, 2, 0.5]}},
      "shapes": [{"type": "triangles", "material": "wall",
        "positions": [[-1,-1,-1],[1,-1,-1],[1,1,-1],[-1,1,-1],[-1,-1,1],[1,-1,1],[1,1,1],[-1,1,1]],
        "indices": [0,1,2, 0,2,3,  4,6,5, 4,7,6,  0,4,5, 0,5,1,  3,2,6, 3,6,7,  0,3,7, 0,7,4,
                    1,5,6, 1,6,2]}]
    })";
  };
  const glm::dvec3 rho(0.5, 0.25, 0.75), Le(1, 2, 0.5);
  RenderResult r = render_ref(scene(100000), 64);
  expect_matches(r, expected_image(r, [&](int, int) { return Le / (glm::dvec3(1.0) - rho); }));
  RenderResult r3 = render_ref(scene(3), 64);
  expect_matches(r3, expected_image(r3, [&](int, int) {
                   return Le * (glm::dvec3(1.0) - rho * rho * rho) / (glm::dvec3(1.0) - rho);
                 }));
}

// Surfaces emit from their front side only: inside an emissive sphere (seen from its back side)
// with a black environment, nothing is seen (exactly 0).
TEST(ReferenceAnalytic, SphereEmitsOutwardsOnly) {
  const char* scene = R"({
    "camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "fov": 60},
    "film": {"width": 8, "height": 8},
    "integrator": {"type": "path", "max_depth": 5},
    "materials": {"lamp": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5], "emission": [1, 1, 1]}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 2, "material": "lamp"}]
  })";
  RenderResult r = render_ref(scene, 16);
  for (float v : r.mean.rgb) EXPECT_EQ(v, 0.0f);
}

// Fresnel reflectance of the exact formula at known points: normal incidence ((eta-1)/(eta+1))^2,
// grazing incidence 1, Brewster's angle (tan = eta) where the p-polarized part vanishes, total
// internal reflection beyond the critical angle, ior 1 transparent, and reciprocity
// F(cos_i, eta) = F(cos_t, 1/eta). Tolerance 1e-12 (double arithmetic).
TEST(ReferenceAnalytic, FresnelDielectric) {
  using lucent::reference::fresnel_dielectric;
  EXPECT_NEAR(fresnel_dielectric(1.0, 1.5), 0.04, 1e-12);
  EXPECT_NEAR(fresnel_dielectric(1.0, 1 / 1.5), 0.04, 1e-12);
  EXPECT_NEAR(fresnel_dielectric(0.0, 1.5), 1.0, 1e-12);
  double tb = std::atan(1.5), ci = std::cos(tb),
         ct = std::sqrt(1 - std::sin(tb) * std::sin(tb) / 2.25);
  double rs = (ci - 1.5 * ct) / (ci + 1.5 * ct);
  EXPECT_NEAR(fresnel_dielectric(ci, 1.5), 0.5 * rs * rs, 1e-12);
  double critical = std::asin(1 / 1.5);
  EXPECT_EQ(fresnel_dielectric(std::cos(critical + 0.01), 1 / 1.5), 1.0);
  EXPECT_LT(fresnel_dielectric(std::cos(critical - 0.01), 1 / 1.5), 1.0);
  EXPECT_NEAR(fresnel_dielectric(0.3, 1.0), 0.0, 1e-12);
  for (double c : {0.1, 0.4, 0.8}) {
    double cos_t = std::sqrt(1 - (1 - c * c) / (1.33 * 1.33));
    EXPECT_NEAR(fresnel_dielectric(c, 1.33), fresnel_dielectric(cos_t, 1 / 1.33), 1e-12);
  }
}

// ior 1 is no interface: F = 0 at every angle, exactly. cos_t^2 was 1 - (1 - cos_i^2) / eta^2,
// which lost cos_i^2 to rounding near grazing: F 3e-11 at cos 1e-6, total reflection (F = 1)
// below 1e-8. A plastic of roughness 0 (GGX alpha 1e-3) multiplies F by its grazing peak, D G2 /
// (4 cos_o cos_i) ~ 1e14 at cos 1e-6: its f at the mirror direction was 15000 times its analytic
// albedo / pi. Elsewhere the formula keeps its values (against long double, to 1e-12)
// and refraction at ior 1 goes straight on.
TEST(ReferenceAnalytic, IorOneReflectsNothing) {
  using lucent::reference::fresnel_dielectric;
  for (double c : {1.0, 0.5, 0.1, 1e-3, 1e-6, 1e-8, 1e-9, 1e-12, 1e-100})
    EXPECT_EQ(fresnel_dielectric(c, 1.0), 0.0) << "cos " << c;
  for (double eta : {0.05, 0.5, 1 / 1.5, 0.99, 1.01, 1.5, 20.0})
    for (double c : {1.0, 0.9, 0.5, 0.2, 0.05, 1e-3, 1e-6}) {
      long double ci = c, e = eta, s2 = (1 - ci * ci) / (e * e);
      if (s2 >= 1) {
        EXPECT_EQ(fresnel_dielectric(c, eta), 1.0) << "cos " << c << " eta " << eta;
        continue;
      }
      long double ct = std::sqrt(1 - s2), rs = (ci - e * ct) / (ci + e * ct),
                  rp = (e * ci - ct) / (e * ci + ct);
      EXPECT_NEAR(fresnel_dielectric(c, eta), double(0.5 * (rs * rs + rp * rp)), 1e-12)
          << "cos " << c << " eta " << eta;
    }

  lucent::Material m;
  m.type = lucent::MaterialType::Plastic;
  m.albedo = glm::dvec3(0.5);
  m.specular = glm::dvec3(1.0);
  m.roughness = 0;
  m.ior = 1;
  const auto plastic = lucent::ref::make_bsdf(lucent::Scene{}, m, lucent::ref::ShadingPoint{});
  for (double co : {0.5, 1e-2, 1e-4, 1e-6, 1e-9}) {
    const glm::dvec3 wo(std::sqrt(1 - co * co), 0, co);
    for (const glm::dvec3& wi : {glm::dvec3(-wo.x, 0, co), glm::dvec3(-wo.x, 1e-3, co),
                                 glm::dvec3(0, 0, 1), glm::dvec3(0.6, 0, 0.8)}) {
      const glm::dvec3 w = glm::normalize(wi);
      EXPECT_DOUBLE_EQ(plastic->eval(wo, w).y, 0.5 / lucent::ref::kPi * w.z)
          << "cos_o " << co << ", wi (" << w.x << ", " << w.y << ", " << w.z << ")";
    }
    const glm::dvec3 through = lucent::ref::refract(wo, glm::dvec3(0, 0, 1), co, 1.0);
    EXPECT_LT(glm::length(through + wo), 1e-15) << "cos_o " << co;
  }
}

// A glass slab (two parallel faces of a closed solid, ior 1.5) seen at normal incidence in front
// of an emitter of radiance Le, black environment: with F = 0.04 at each face the transmitted
// radiance, summed over internal reflections, is Le (1 - F)^2 / (1 - F^2) = Le (1 - F)/(1 + F)
// (the 1/2.25 on entry and 2.25 on exit cancel). The camera sees the slab within 0.25 degrees of
// normal incidence (F changes by < 1e-5 there).
TEST(ReferenceAnalytic, GlassSlabAtNormalIncidence) {
  const char* scene = R"({
    "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 0.5},
    "film": {"width": 16, "height": 16},
    "integrator": {"type": "path", "max_depth": 1000},
    "materials": {"glass": {"type": "dielectric", "ior": 1.5},
                  "lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [1, 2, 4]}},
    "shapes": [
      {"type": "triangles", "material": "glass",
       "positions": [[-5,-5,1],[5,-5,1],[5,5,1],[-5,5,1], [-5,-5,0.5],[5,-5,0.5],[5,5,0.5],[-5,5,0.5]],
       "indices": [0,1,2, 0,2,3,  4,6,5, 4,7,6]},
      {"type": "triangles", "material": "lamp",
       "positions": [[-5,-5,-1],[5,-5,-1],[5,5,-1],[-5,5,-1]], "indices": [0,1,2, 0,2,3]}]
  })";
  // each sample is Le or 0 (transmitted or not), p = 0.92: 1024 spp so that the variance the
  // z-test estimates from a pixel's samples is close to p (1 - p) (at 256 spp a pixel that drew
  // 3 sd too many transmissions gets a z near 5 from its smaller estimated variance)
  RenderResult r = render_ref(scene, 1024);
  const double F = 0.04, k = (1 - F) / (1 + F);
  expect_matches(r, expected_image(r, [&](int, int) { return k * glm::dvec3(1, 2, 4); }));
}

/// A mirror plane z = 0 of reflectance `rho` (a JSON array) under an emitting quad z = 3 (Le =
/// (1, 2, 3), front facing down), seen from straight above at height 2 (16 x 16 pixels); path
/// tracing with max_depth 4 and Russian roulette from `rr_depth` segments.
std::string mirror_under_lamp(const std::string& rho, int rr_depth) {
  return R"({
    "camera": {"position": [0, 0, 2], "look_at": [0, 0, 0], "fov": 30},
    "film": {"width": 16, "height": 16},
    "integrator": {"type": "path", "max_depth": 4, "rr_depth": )" +
         std::to_string(rr_depth) + R"(},
    "materials": {"mirror": {"type": "mirror", "reflectance": )" +
         rho + R"(},
                  "lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [1, 2, 3]}},
    "shapes": [
      {"type": "triangles", "material": "mirror",
       "positions": [[-5,-5,0],[5,-5,0],[5,5,0],[-5,5,0]], "indices": [0,1,2, 0,2,3]},
      {"type": "triangles", "material": "lamp",
       "positions": [[-5,-5,3],[5,-5,3],[5,5,3],[-5,5,3]], "indices": [0,2,1, 0,3,2]}]
  })";
}

// A mirror (reflectance rho) showing an emitter: the camera looks down at a mirror plane; every
// reflected ray meets an emitting quad (front facing down) above the camera, so every pixel is
// rho * Le exactly.
TEST(ReferenceAnalytic, MirrorShowsEmitter) {
  const std::string scene = mirror_under_lamp("[0.5, 0.6, 0.7]", 4);
  RenderResult r = render_ref(scene, 4);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      EXPECT_NEAR(r.mean.pixel(x, y)[0], 0.5 * 1, 1e-6);
      EXPECT_NEAR(r.mean.pixel(x, y)[1], 0.6 * 2, 1e-6);
      EXPECT_NEAR(r.mean.pixel(x, y)[2], 0.7 * 3, 1e-6);
    }
}

// Two parallel mirrors of reflectance 1 under a sky of 1, the camera between them looking 5.7
// degrees off their normal: each ray bounces about 50000 times before it leaves their edge and
// sees the sky, so every pixel is 1 (the scene's max_depth, 100000, is not reached). The
// reference's Whitted integrator recursed once per bounce and overflowed its thread's stack here
// (a crash); it now keeps its pending rays in a list.
TEST(ReferenceAnalytic, WhittedChainOfFiftyThousandMirrorBounces) {
  RenderResult r = render_ref(R"({
    "camera": {"position": [0, 0, 0], "look_at": [0.1, 0, -1], "up": [0, 1, 0], "fov": 0.5},
    "film": {"width": 4, "height": 4},
    "integrator": {"type": "whitted", "max_depth": 100000},
    "materials": {"m": {"type": "mirror", "reflectance": [1, 1, 1]}},
    "shapes": [
      {"type": "triangles", "material": "m", "indices": [0, 1, 2, 0, 2, 3],
       "positions": [[-1e4, -1e4, -1], [1e4, -1e4, -1], [1e4, 1e4, -1], [-1e4, 1e4, -1]]},
      {"type": "triangles", "material": "m", "indices": [0, 2, 1, 0, 3, 2],
       "positions": [[-1e4, -1e4, 1], [1e4, -1e4, 1], [1e4, 1e4, 1], [-1e4, 1e4, 1]]}],
    "lights": [{"type": "environment", "radiance": [1, 1, 1]}]})",
                              1);
  EXPECT_GT(r.rays, 16u * 40000u);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x)
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(r.mean.pixel(x, y)[c], 1.0, 1e-9) << x << "," << y;
}

// Russian roulette (docs/rendering-model.md, "Integrators"): once a path has rr_depth segments it
// survives with probability q = max(beta) while q < 1, its throughput divided by q. The camera
// sees the emitter of MirrorShowsEmitter through a mirror of reflectance rho with RR from the
// first bounce (rr_depth 1): every sample is either rho Le / q (probability q) or 0, with
// q = min(1, max(rho)).
// - max(rho) = 1: the path is never cut, every sample is rho Le exactly: the mean within 1e-6,
//   the per-pixel sample variance 0 (a cap on the survival probability below 1, as the
//   reference once had with 0.95, kills some of these paths: variance > 0).
// - max(rho) = 0.8: the survival probability is 0.8: the per-pixel variance per channel is
//   (rho Le / q)^2 q (1 - q); its mean over the 256 pixels (64 samples each) estimates that with
//   a relative standard deviation of 1.2% (Bernoulli moments); 6% allowed. The means match
//   rho Le (the default comparison).
TEST(ReferenceAnalytic, RussianRouletteSurvivesWithMaxThroughput) {
  const glm::dvec3 Le(1, 2, 3);
  {
    const glm::dvec3 rho(1, 0.6, 0.3);
    RenderResult r = render_ref(mirror_under_lamp("[1, 0.6, 0.3]", 1), 16);
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x)
        for (int c = 0; c < 3; ++c) {
          EXPECT_NEAR(r.mean.pixel(x, y)[c], rho[c] * Le[c], 1e-6) << x << "," << y;
          EXPECT_LE(r.variance.pixel(x, y)[c], 1e-10) << x << "," << y;
        }
  }
  {
    const glm::dvec3 rho(0.8, 0.4, 0.2);
    const double q = 0.8;
    RenderResult r = render_ref(mirror_under_lamp("[0.8, 0.4, 0.2]", 1), 64);
    expect_matches(r, expected_image(r, [&](int, int) { return rho * Le; }));
    for (int c = 0; c < 3; ++c) {
      double sum = 0;
      for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) sum += r.variance.pixel(x, y)[c];
      const double want = std::pow(rho[c] * Le[c] / q, 2) * q * (1 - q);
      EXPECT_NEAR(sum / 256, want, 0.06 * want) << "channel " << c;
    }
  }
}

// The AOV integrators at known points: a plane z = 0 seen from straight above at height 5 gives
// depth 5 / cos(angle off axis), normal (0, 0, 1), albedo; ambient occlusion of an open plane
// is 1, and 0 on a miss. Tolerance 1e-6 (tiny filter).
TEST(ReferenceAnalytic, AovsOnAPlane) {
  auto scene = [](const char* integrator) {
    return std::string(R"({
      "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 30},
      "film": {"width": 8, "height": 8, "filter": {"type": "box", "radius": 0.0001}},
      "integrator": {"type": ")") +
           integrator + R"("},
      "materials": {"m": {"type": "plastic", "albedo": [0.1, 0.2, 0.3]}},
      "shapes": [{"type": "triangles", "material": "m",
                  "positions": [[-9,-9,0],[9,-9,0],[9,9,0],[-9,9,0]], "indices": [0,1,2, 0,2,3]}]
    })";
  };
  RenderResult depth = render_ref(scene("depth"), 2), normal = render_ref(scene("normal"), 2);
  RenderResult albedo = render_ref(scene("albedo"), 2), ao = render_ref(scene("ao"), 16);
  const double t = std::tan(15.0 * M_PI / 180.0);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      double nx = (2.0 * (x + 0.5) / 8 - 1) * t, ny = (1 - 2.0 * (y + 0.5) / 8) * t;
      EXPECT_NEAR(depth.mean.pixel(x, y)[0], 5 * std::sqrt(1 + nx * nx + ny * ny), 1e-5);
      EXPECT_NEAR(normal.mean.pixel(x, y)[2], 1.0, 1e-6);
      EXPECT_NEAR(albedo.mean.pixel(x, y)[2], 0.3, 1e-6);
      EXPECT_NEAR(ao.mean.pixel(x, y)[0], 1.0, 1e-6);
    }
}

}  // namespace

}  // namespace test_reference_analytic
