// The reference's rough dielectric (src/reference/bsdf/rough_dielectric.cpp: GGX microfacet
// reflection and transmission, Walter et al. 2007) checked through the reference's own API: the
// generalized reciprocity of its BTDF, its energy balance against its sampling weights and
// against a quadrature of eval(), and next-event estimation through the surface in the path
// integrator (a hand-built lucent::Scene, since the scene loader does not know the type yet).
// Its sampling against its pdf: test_reference_sampling.cpp, BsdfRoughDielectric*.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "lucent/compare.hpp"
#include "lucent/reference.hpp"
#include "reference/bsdf/bsdf.hpp"
#include "support.hpp"

namespace test_reference_rough_dielectric {

namespace {

using glm::dvec3;
using lucent::ref::Bsdf;
using lucent::ref::BsdfSample;
using lucent::ref::kPi;

constexpr double kIor = 1.5;

lucent::Material rough_glass(double roughness, dvec3 tint = dvec3(1.0)) {
  lucent::Material m;
  m.name = "rough";
  m.type = lucent::MaterialType::RoughDielectric;
  m.specular = tint;
  m.ior = kIor;
  m.roughness = roughness;
  return m;
}

/// The BSDF at a surface of normal (0, 0, 1) seen from above (front side, eta = ior) or from
/// below (back side, eta = 1 / ior; the BSDF's normal faces wo).
std::unique_ptr<Bsdf> bsdf(const lucent::Material& m, bool from_above) {
  lucent::ref::ShadingPoint sp;
  sp.n = sp.ng = from_above ? dvec3(0, 0, 1) : dvec3(0, 0, -1);
  sp.front = from_above;
  return lucent::ref::make_bsdf(lucent::Scene{}, m, sp);
}

dvec3 uniform_sphere(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double z = 1 - 2 * u(rng), r = std::sqrt(std::max(0.0, 1 - z * z)), phi = 2 * kPi * u(rng);
  return dvec3(r * std::cos(phi), r * std::sin(phi), z);
}

/// A direction at angle theta from `axis` ((0, 0, +-1)), azimuth 0.7.
dvec3 at_angle(double theta, double axis_z) {
  return dvec3(std::sin(theta) * std::cos(0.7), std::sin(theta) * std::sin(0.7),
               axis_z * std::cos(theta));
}

// Generalized reciprocity (Veach 1997, sec. 5.3; Walter et al. 2007, sec. 5.3): for radiance
// transport, f(wo, wi) / eta(wo)^2 = f(wi, wo) / eta(wi)^2, with eta(w) the index of the medium
// on w's side; so transmission from air into glass and back differ by ior^2 = 2.25, while
// reflection is symmetric on either side. f = eval / |cos(wi)|, evaluated with the BSDF of wo's
// side (its normal facing wo). 20000 random pairs per roughness (wo uniform over a hemisphere, wi
// over the sphere); tolerance 1e-9 relative plus 1e-12 absolute (double rounding: where f is
// tiny, wo or wi nearly grazes the microfacet and the two evaluations' half vectors lose
// relative precision; measured worst: 3e-11 relative above f = 1e-3, 3.5e-14 absolute below);
// at least 2000 pairs with f > 0 in each of the three cases, so that the test is not vacuous.
TEST(ReferenceRoughDielectric, GeneralizedReciprocity) {
  std::mt19937_64 rng(0x5eed2001u);
  for (double roughness : {0.05, 0.3, 1.0}) {
    const lucent::Material m = rough_glass(roughness, dvec3(1.0, 0.8, 0.6));
    const auto above = bsdf(m, true), below = bsdf(m, false);
    int transmitted = 0, reflected_above = 0, reflected_below = 0;
    for (int i = 0; i < 20000; ++i) {
      dvec3 wo = uniform_sphere(rng), wi = uniform_sphere(rng);
      if (wo.z < 0) wo.z = -wo.z;  // wo above: air, eta(wo) = 1
      const dvec3 f_oi = above->eval(wo, wi) / std::abs(wi.z);
      if (wi.z < 0) {  // wi in the glass: eta(wi) = ior, and f(wi, wo) is the inside BSDF's
        const dvec3 f_io = below->eval(wi, wo) / std::abs(wo.z);
        for (int c = 0; c < 3; ++c)
          ASSERT_NEAR(f_io[c], kIor * kIor * f_oi[c], 1e-9 * f_io[c] + 1e-12)
              << "roughness " << roughness << " transmission, channel " << c;
        transmitted += f_oi.x > 0;
      } else {
        const dvec3 f_io = above->eval(wi, wo) / std::abs(wo.z);
        ASSERT_NEAR(f_io.x, f_oi.x, 1e-9 * f_io.x + 1e-12) << "roughness " << roughness;
        reflected_above += f_oi.x > 0;
        // the same pair mirrored below the surface: reflection inside the glass
        const dvec3 wo_b(wo.x, wo.y, -wo.z), wi_b(wi.x, wi.y, -wi.z);
        const double g_oi = below->eval(wo_b, wi_b).x / std::abs(wi_b.z);
        const double g_io = below->eval(wi_b, wo_b).x / std::abs(wo_b.z);
        ASSERT_NEAR(g_io, g_oi, 1e-9 * g_io + 1e-12) << "roughness " << roughness;
        reflected_below += g_oi > 0;
      }
    }
    EXPECT_GE(transmitted, 2000) << "roughness " << roughness;
    EXPECT_GE(reflected_above, 2000) << "roughness " << roughness;
    EXPECT_GE(reflected_below, 2000) << "roughness " << roughness;
  }
}

/// Mean sampling weights from wo over N samples (white tint): `radiance`, the directional albedo
/// of radiance transport (transmitted weights carry the 1 / eta^2); `energy`, with the
/// transmitted weights times eta^2 (the fraction of the light's power that the surface scatters
/// rather than absorbs: at most 1, and 1 for a smooth interface); their standard errors.
struct Albedo {
  double radiance = 0, energy = 0, radiance_se = 0, energy_se = 0;
};

Albedo sampled_albedo(const Bsdf& b, const dvec3& wo, double eta, int N, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double sr = 0, sr2 = 0, se = 0, se2 = 0;
  const double side = wo.z > 0 ? 1 : -1;
  for (int i = 0; i < N; ++i) {
    double a = u(rng), b1 = u(rng), b2 = u(rng);
    BsdfSample s = b.sample(wo, a, b1, b2);
    if (!s.valid) continue;
    double r = s.weight.x, e = s.wi.z * side < 0 ? r * eta * eta : r;
    sr += r;
    sr2 += r * r;
    se += e;
    se2 += e * e;
  }
  Albedo a;
  a.radiance = sr / N;
  a.energy = se / N;
  a.radiance_se = std::sqrt(std::max(0.0, sr2 / N - a.radiance * a.radiance) / N);
  a.energy_se = std::sqrt(std::max(0.0, se2 / N - a.energy * a.energy) / N);
  return a;
}

// Energy balance from the sampling weights (2^15 samples per case), from above (eta = 1.5) and
// below (eta = 1/1.5), roughness 1e-3 to 1, incidence 0.05 to 1.55 rad:
// - the energy albedo never exceeds 1 (by more than 4 standard errors): a single-scattering
//   microfacet surface loses light (masking), it never creates any;
// - at roughness 1e-3 (alpha's floor) the surface is nearly smooth: the energy albedo is 1 and
//   the radiance albedo the smooth dielectric's F + (1 - F) / eta^2, F = F(cos theta_o), within
//   2e-3 (masking still costs 1 - G2 ~ 5e-4 at 1.55 rad) plus 5 standard errors;
// - the energy albedo decreases as roughness grows, by more than 4 combined standard errors from
//   1e-3 to 1 at grazing incidence (1.4 rad), where masking is strongest.
TEST(ReferenceRoughDielectric, EnergyFromSampling) {
  const int N = 1 << 15;
  for (bool from_above : {true, false}) {
    const double eta = from_above ? kIor : 1 / kIor, axis = from_above ? 1 : -1;
    for (double theta : {0.05, 0.5, 1.0, 1.4, 1.55}) {
      const dvec3 wo = at_angle(theta, axis);
      Albedo smooth, rough;
      for (double roughness : {1e-3, 0.01, 0.1, 0.3, 0.6, 1.0}) {
        const auto b = bsdf(rough_glass(roughness), from_above);
        Albedo a =
            sampled_albedo(*b, wo, eta, N, 0x5eed3000u + int(theta * 100) + int(roughness * 1e4));
        const std::string where = std::string(from_above ? "above" : "below") + ", theta " +
                                  std::to_string(theta) + ", roughness " +
                                  std::to_string(roughness);
        EXPECT_LE(a.energy, 1 + 4 * a.energy_se + 1e-12) << where;
        if (roughness == 1e-3) {
          smooth = a;
          EXPECT_NEAR(a.energy, 1.0, 2e-3 + 5 * a.energy_se) << where;
          const double F = lucent::reference::fresnel_dielectric(std::cos(theta), eta);
          EXPECT_NEAR(a.radiance, F + (1 - F) / (eta * eta), 2e-3 + 5 * a.radiance_se) << where;
        }
        if (roughness == 1.0) rough = a;
      }
      if (theta == 1.4) {
        EXPECT_LT(rough.energy, smooth.energy - 4 * std::hypot(rough.energy_se, smooth.energy_se))
            << (from_above ? "above" : "below");
      }
    }
  }
}

// The radiance albedo from the sampling weights (2^18 samples) against the integral of eval()
// over the sphere of wi (midpoint rule, 768 x 768 cells in (cos theta, phi) about the normal:
// quadrature error below 1e-4 for these roughnesses), from above and below, roughness 0.2 to 1,
// incidence 0.3 and 1.2 rad: equal within 5 standard errors plus 5e-4. (eval and sample share
// no code path but the Fresnel term and D: a pdf that is not the density of sample() would bias
// the weights; the chi-square tests check that density directly.)
void albedo_against_quadrature(bool from_above) {
  const double eta = from_above ? kIor : 1 / kIor, axis = from_above ? 1 : -1;
  const int M = 768;
  for (double roughness : {0.2, 0.5, 1.0}) {
    const auto b = bsdf(rough_glass(roughness), from_above);
    for (double theta : {0.3, 1.2}) {
      const dvec3 wo = at_angle(theta, axis);
      double quad = 0;
      for (int i = 0; i < M; ++i) {
        const double z = -1 + 2 * (i + 0.5) / M, r = std::sqrt(1 - z * z);
        for (int j = 0; j < M; ++j) {
          const double phi = 2 * kPi * (j + 0.5) / M;
          quad += b->eval(wo, dvec3(r * std::cos(phi), r * std::sin(phi), z)).x;
        }
      }
      quad *= (2.0 / M) * (2 * kPi / M);
      Albedo a = sampled_albedo(*b, wo, eta, 1 << 18,
                                0x5eed4000u + int(theta * 10) + int(roughness * 100));
      EXPECT_NEAR(a.radiance, quad, 5 * a.radiance_se + 5e-4)
          << (from_above ? "above" : "below") << ", roughness " << roughness << ", theta " << theta;
    }
  }
}

TEST(ReferenceRoughDielectric, AlbedoMatchesQuadratureFromAbove) {
  albedo_against_quadrature(true);
}

TEST(ReferenceRoughDielectric, AlbedoMatchesQuadratureFromBelow) {
  albedo_against_quadrature(false);
}

// Next-event estimation through the surface: a rough dielectric plane z = 0 (front side up), an
// emitting square on the other side of it facing the plane, black environment, path tracing with
// max_depth 2 (the plane's direct light only: light sampling through the plane, BSDF-sampled
// refracted rays that hit the emitter, MIS between them). Seen from above (eta = 1.5, emitter
// below) and from below (eta = 1 / 1.5, emitter above; part of it beyond the critical angle).
// A box filter of radius 1e-4 pixel makes each pixel the radiance along its centre ray:
// the integral over the emitter of f(wo, wi) |cos_i| Le cos_l / d^2 dA, computed by a 256 x 256
// midpoint rule with the BSDF's eval (checked above). Per-pixel z-tests and the image-mean test
// of lucent::compare_images at family-wise alpha 0.01 (8 x 8 pixels, 2048 samples each).
// Light sampling that ignored the far side, or a shadow ray leaving from the wrong side, would
// lose most of the light (MIS gives it most of the weight here).
void nee_through_surface(bool from_above) {
  const double cam_z = from_above ? 3 : -3, lamp_z = from_above ? -0.8 : 0.8;
  const dvec3 Le(1.0, 2.0, 3.0), tint(1.0, 0.8, 0.6);
  lucent::Scene scene;
  scene.path = "rough-plane.json";
  scene.camera.position = dvec3(0, 0, cam_z);
  scene.camera.look_at = dvec3(0, 0, 0);
  scene.camera.up = dvec3(0, 1, 0);
  scene.camera.fov_degrees = 30;
  scene.film.width = scene.film.height = 8;
  scene.film.filter = {lucent::FilterType::Box, 1e-4};
  scene.integrator.type = lucent::IntegratorType::Path;
  scene.integrator.max_depth = 2;
  scene.materials.push_back(rough_glass(0.3, tint));
  lucent::Material lamp;
  lamp.name = "lamp";
  lamp.albedo = dvec3(0.0);
  lamp.emission = Le;
  scene.materials.push_back(lamp);
  // the plane (front +z), then the emitter, 2 x 2 centred at (0.3, 0.2), front towards the plane
  const double s = 50, x0 = -0.7, x1 = 1.3, y0 = -0.8, y1 = 1.2;
  scene.positions = {{-s, -s, 0},      {s, -s, 0},       {s, s, 0},        {-s, s, 0},
                     {x0, y0, lamp_z}, {x1, y0, lamp_z}, {x1, y1, lamp_z}, {x0, y1, lamp_z}};
  auto tri = [&](int a, int b, int c, int material) {
    lucent::Triangle t;
    t.v[0] = a;
    t.v[1] = b;
    t.v[2] = c;
    t.material = material;
    scene.triangles.push_back(t);
  };
  tri(0, 1, 2, 0);
  tri(0, 2, 3, 0);
  if (from_above) {  // facing up
    tri(4, 5, 6, 1);
    tri(4, 6, 7, 1);
  } else {  // facing down
    tri(4, 6, 5, 1);
    tri(4, 7, 6, 1);
  }
  lucent::ReferenceOptions options;
  options.spp = 2048;
  lucent::RenderResult r = lucent::render_reference(scene, options);
  ASSERT_EQ(r.nonfinite, 0u);

  // the expected image: camera basis of docs/rendering-model.md (looking along -z from above:
  // right = +x; along +z from below: right = -x; up = +y either way)
  const auto b = bsdf(scene.materials[0], from_above);
  const double right = from_above ? 1 : -1, th = std::tan(15 * kPi / 180);
  const int M = 256;
  const double dA = (x1 - x0) * (y1 - y0) / (M * M);
  lucent::RenderResult expected;
  expected.mean = r.mean;
  for (int py = 0; py < 8; ++py)
    for (int px = 0; px < 8; ++px) {
      const double ndc_x = (2 * (px + 0.5) / 8 - 1) * th, ndc_y = (1 - 2 * (py + 0.5) / 8) * th;
      const dvec3 p(right * ndc_x * std::abs(cam_z), ndc_y * std::abs(cam_z), 0);
      const dvec3 wo = glm::normalize(scene.camera.position - p);
      dvec3 sum(0.0);
      for (int i = 0; i < M; ++i)
        for (int j = 0; j < M; ++j) {
          const dvec3 y(x0 + (x1 - x0) * (i + 0.5) / M, y0 + (y1 - y0) * (j + 0.5) / M, lamp_z);
          const dvec3 d = y - p;
          const double d2 = glm::dot(d, d);
          const dvec3 wi = d / std::sqrt(d2);
          sum += b->eval(wo, wi) * Le * (std::abs(wi.z) / d2) * dA;
        }
      for (int c = 0; c < 3; ++c) expected.mean.pixel(px, py)[c] = static_cast<float>(sum[c]);
    }
  lucent::CompareResult c = lucent::compare_images(r, expected);
  EXPECT_TRUE(c.passed) << (from_above ? "from above\n" : "from below\n") << c.summary();
  EXPECT_GT(c.mean_b[0], 0.02) << "the emitter must light the pixels";
}

TEST(ReferenceRoughDielectric, LightThroughTheSurfaceFromAbove) { nee_through_surface(true); }

TEST(ReferenceRoughDielectric, LightThroughTheSurfaceFromBelow) { nee_through_surface(false); }

// Whitted and the albedo AOV see a rough dielectric as the smooth one (deterministic Fresnel
// split about the shading normal; albedo = tint): a glass sphere and a glass triangle (with
// vertex normals) in front of a diffuse floor under a point light and an environment render
// exactly the same images with either material type.
TEST(ReferenceRoughDielectric, WhittedAndAlbedoAsTheSmoothDielectric) {
  for (lucent::IntegratorType integrator :
       {lucent::IntegratorType::Whitted, lucent::IntegratorType::Albedo}) {
    lucent::Scene scene = lucent::test::scene_from(R"({
      "camera": {"position": [0, 1, 5], "look_at": [0, 0, 0], "fov": 40},
      "film": {"width": 24, "height": 16},
      "integrator": {"type": "whitted", "max_depth": 6},
      "materials": {"glass": {"type": "dielectric", "ior": 1.5, "tint": [1, 0.8, 0.6]},
                    "floor": {"type": "diffuse", "albedo": [0.6, 0.5, 0.4]}},
      "shapes": [
        {"type": "sphere", "center": [-0.6, 0, 0], "radius": 0.8, "material": "glass"},
        {"type": "triangles", "material": "glass",
         "positions": [[0.3, -0.8, 0.5], [1.6, -0.8, 0.2], [1.0, 0.9, 0.4]], "indices": [0, 1, 2],
         "normals": [[0.3, 0, 1], [-0.2, 0.1, 1], [0, -0.3, 1]]},
        {"type": "triangles", "material": "floor",
         "positions": [[-5,-0.8,-5],[5,-0.8,-5],[5,-0.8,5],[-5,-0.8,5]], "indices": [0,2,1, 0,3,2]}],
      "lights": [{"type": "point", "position": [2, 4, 3], "intensity": [30, 30, 30]},
                 {"type": "environment", "radiance": [0.2, 0.3, 0.4]}]
    })");
    scene.integrator.type = integrator;
    lucent::ReferenceOptions options;
    options.spp = 2;
    const lucent::RenderResult smooth = lucent::render_reference(scene, options);
    lucent::Material& glass = scene.materials[scene.find_material("glass")];
    glass.type = lucent::MaterialType::RoughDielectric;
    glass.roughness = 0.4;
    const lucent::RenderResult rough = lucent::render_reference(scene, options);
    EXPECT_EQ(smooth.mean.rgb, rough.mean.rgb);
    double sum = 0;
    for (float v : smooth.mean.rgb) sum += v;
    EXPECT_GT(sum, 0.0);
  }
}

}  // namespace

}  // namespace test_reference_rough_dielectric
