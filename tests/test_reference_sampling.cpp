// The reference integrator's sampling (src/reference/) against its own pdfs, by chi-square tests
// that mirror the device's (test_kernel_bsdf.cpp, test_kernel_light_sampling.cpp): BSDF sampling
// against Bsdf::pdf, and next-event estimation's light sampling (uniform light choice, uniform
// area points on spheres and triangles, uniform directions for the environment) against
// Light::pdf, the pdfs the reference uses for MIS.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "reference/bsdf/bsdf.hpp"
#include "reference/light/light.hpp"
#include "support.hpp"

namespace test_reference_sampling {

namespace {

using glm::dvec3;
using lucent::ref::kPi;

struct Frame {
  dvec3 t, b, n;
  dvec3 to_world(double x, double y, double z) const { return x * t + y * b + z * n; }
};

Frame frame_of(const dvec3& n) {
  dvec3 a = std::abs(n.x) > 0.5 ? dvec3(0, 1, 0) : dvec3(1, 0, 0);
  dvec3 t = glm::normalize(glm::cross(a, n));
  return {t, glm::cross(n, t), n};
}

/// Draws one sample: returns false when the sampler reports failure (or a delta sample, which
/// has no density), else the direction.
using SampleFn = std::function<bool(std::mt19937_64&, dvec3&)>;
using PdfFn = std::function<double(const dvec3&)>;
/// Adds N times the integral of a part of the pdf over each cell (indexed ti * NP + pi) that
/// `pdf` leaves out.
using ExtraFn = std::function<void(int N, std::vector<double>& expected)>;

// Draws N samples (2^18 unless told), bins them over (cos theta, phi) of `frame` with cos theta
// in [z_lo, 1] (NT x NP cells), and compares the counts with N times the pdf integrated over each
// cell (`pdf` by a SUB x SUB midpoint rule, refined to FINE x FINE where the SUB^2 values differ
// by more than 1% (lobe peaks, light and horizon edges) and in the neighbours of such cells, so
// that the quadrature error stays well below the counting noise; plus `extra`). Cells with
// expected count < 5 are pooled into one. Pearson's statistic; fails when the p-value is below
// 1e-4 (a handful of cases at a family-wise alpha ~ 1e-3). Also: the pdf integral over the
// binned region equals the fraction of successful samples (within 5 binomial standard
// deviations plus 0.2% for the quadrature), and no successful sample falls outside the region.
void chi_square(const char* name, const Frame& frame, double z_lo, int NT, int NP,
                const SampleFn& sample, const PdfFn& pdf, std::uint64_t seed,
                const ExtraFn& extra = nullptr, int N = 1 << 18) {
  const int SUB = 4, FINE = 32;
  std::mt19937_64 rng(seed);
  std::vector<double> observed(NT * NP, 0.0);
  int produced = 0, outside = 0;
  const double zr = 1 - z_lo;
  for (int i = 0; i < N; ++i) {
    dvec3 w;
    if (!sample(rng, w)) continue;
    ++produced;
    double z = std::clamp(glm::dot(w, frame.n), -1.0, 1.0);
    if (z < z_lo) {
      ++outside;
      continue;
    }
    int ti = std::min(NT - 1, int((z - z_lo) / zr * NT));
    double phi = std::atan2(glm::dot(w, frame.b), glm::dot(w, frame.t));
    if (phi < 0) phi += 2 * kPi;
    int pi = std::min(NP - 1, int(phi / (2 * kPi) * NP));
    observed[ti * NP + pi] += 1;
  }
  EXPECT_EQ(outside, 0) << name << ": successful samples outside the binned region";

  // pdf values at sub x sub midpoints of cell c
  auto cell_pdf = [&](int c, int sub, std::vector<double>& v) {
    v.clear();
    int ti = c / NP, pi = c % NP;
    for (int i = 0; i < sub; ++i)
      for (int j = 0; j < sub; ++j) {
        double z = z_lo + zr * (ti + (i + 0.5) / sub) / NT;
        double phi = 2 * kPi * (pi + (j + 0.5) / sub) / NP;
        double r = std::sqrt(std::max(0.0, 1 - z * z));
        v.push_back(pdf(frame.to_world(r * std::cos(phi), r * std::sin(phi), z)));
      }
  };
  const double cell_area = (zr / NT) * (2 * kPi / NP);  // dz dphi = solid angle
  std::vector<double> expected(NT * NP, 0.0), v;
  std::vector<char> mark(NT * NP, 0);
  for (int c = 0; c < NT * NP; ++c) {
    cell_pdf(c, SUB, v);
    double lo = *std::min_element(v.begin(), v.end()), hi = *std::max_element(v.begin(), v.end());
    double sum = 0;
    for (double x : v) sum += x;
    expected[c] = sum / (SUB * SUB) * cell_area * N;
    // an edge that clips a cell's corner may miss all its points: refine the neighbours too
    if (hi > lo * 1.01)
      for (int dt = -1; dt <= 1; ++dt)
        for (int dp = -1; dp <= 1; ++dp) {
          int t = c / NP + dt, ph = (c % NP + dp + NP) % NP;
          if (t >= 0 && t < NT) mark[t * NP + ph] = 1;
        }
  }
  for (int c = 0; c < NT * NP; ++c) {
    if (!mark[c]) continue;
    cell_pdf(c, FINE, v);
    double sum = 0;
    for (double x : v) sum += x;
    expected[c] = sum / (FINE * FINE) * cell_area * N;
  }
  if (extra) extra(N, expected);
  double integral = 0;
  for (double e : expected) integral += e / N;
  // binomial counting noise (5 sigma) plus a quadrature allowance
  const double frac = double(produced) / N;
  const double tol = 5 * std::sqrt(frac * (1 - frac) / N) + 2e-3 * std::max(frac, integral);
  EXPECT_NEAR(integral, frac, tol) << name << ": pdf integral vs sampling success";

  lucent::test::PooledChi2 c = lucent::test::pooled_chi2(observed, expected);
  if (c.pooled_expected < 5) {
    EXPECT_LE(c.pooled_observed, 20) << name << ": many samples where the pdf is ~0";
  }
  ASSERT_GE(c.cells, 20) << name << ": too few populated bins for a meaningful test";
  double pval = lucent::test::chi2_pvalue(c.chi2, c.cells - 1);
  EXPECT_GT(pval, 1e-4) << name << ": chi2 " << c.chi2 << " over " << c.cells << " cells";
}

// ------------------------------------------------------------------------------------------
// BSDFs

lucent::Material material(lucent::MaterialType type, dvec3 albedo, double spec, double rough) {
  lucent::Material m;
  m.type = type;
  m.albedo = albedo;
  m.specular = dvec3(spec);
  m.roughness = rough;
  m.ior = 1.5;
  return m;
}

// Samples a BSDF at a tilted normal (world frame) and bins over the hemisphere around it (the
// whole sphere from z_lo = -1, for transmission; NT x NP cells, N samples); also checks that each
// sample's weight equals eval / pdf at its direction and its pdf equals Bsdf::pdf. `front`: wo is
// on the front side of the surface (dielectrics: eta = ior, else 1 / ior).
void chi_square_bsdf(const char* name, const lucent::Material& m, double wo_theta,
                     bool front = true, double z_lo = 0.0, int NT = 16, int NP = 32,
                     int N = 1 << 18) {
  lucent::ref::ShadingPoint sp;
  sp.n = sp.ng = glm::normalize(dvec3(0.3, -0.5, 0.8));
  sp.front = front;
  const std::unique_ptr<lucent::ref::Bsdf> bsdf = lucent::ref::make_bsdf(lucent::Scene{}, m, sp);
  const lucent::ref::Bsdf& b = *bsdf;
  Frame f = frame_of(sp.n);
  const double st = std::sin(wo_theta);
  const dvec3 wo = f.to_world(st * std::cos(0.4), st * std::sin(0.4), std::cos(wo_theta));
  int checked = 0;
  auto sample = [&](std::mt19937_64& rng, dvec3& w) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    double a = u(rng), b1 = u(rng), b2 = u(rng);
    lucent::ref::BsdfSample s = b.sample(wo, a, b1, b2);
    if (!s.valid || s.delta) return false;
    w = s.wi;
    if (checked < 4000) {
      ++checked;
      double pdf = b.pdf(wo, s.wi);
      dvec3 fc = b.eval(wo, s.wi);
      EXPECT_NEAR(s.pdf, pdf, 1e-9 * pdf) << name;
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(s.weight[c], fc[c] / pdf, 1e-9 * std::max(1.0, fc[c] / pdf)) << name;
    }
    return true;
  };
  auto pdf = [&](const dvec3& wi) { return b.pdf(wo, wi); };
  chi_square(name, f, z_lo, NT, NP, sample, pdf, 0x5eed0001u + std::uint64_t(wo_theta * 1000),
             nullptr, N);
}

using lucent::MaterialType;

TEST(ReferenceSampling, BsdfDiffuse) {
  chi_square_bsdf("diffuse", material(MaterialType::Diffuse, dvec3(0.5, 0.6, 0.7), 0, 0), 0.7);
}

TEST(ReferenceSampling, BsdfConductorRough) {
  chi_square_bsdf("conductor 0.5", material(MaterialType::Conductor, dvec3(0.0), 0.9, 0.5), 0.6);
}

TEST(ReferenceSampling, BsdfConductorSmooth) {
  chi_square_bsdf("conductor 0.15", material(MaterialType::Conductor, dvec3(0.0), 0.9, 0.15), 1.2);
}

TEST(ReferenceSampling, BsdfPlastic) {
  chi_square_bsdf("plastic", material(MaterialType::Plastic, dvec3(0.3, 0.5, 0.8), 1.0, 0.2), 0.9);
}

// Diffuse plus mirror: the diffuse directions (uniform over the hemisphere, chosen half the time)
// against Bsdf::pdf, which integrates to the non-delta half; the mirror ones (the other half,
// left out of the bins) are the reflection of wo with weight reflectance / (1/2).
TEST(ReferenceSampling, BsdfDiffuseMirror) {
  lucent::Material m = material(MaterialType::DiffuseMirror, dvec3(0.05, 0.2, 0.9), 0, 0);
  m.specular = dvec3(0.9, 0.3, 0.0);
  chi_square_bsdf("diffuse_mirror", m, 0.8);
  lucent::ref::ShadingPoint sp;
  sp.n = sp.ng = glm::normalize(dvec3(0.3, -0.5, 0.8));
  auto b = lucent::ref::make_bsdf(lucent::Scene{}, m, sp);
  const dvec3 wo = glm::normalize(dvec3(0.6, 0.1, 0.5));
  int deltas = 0;
  for (int i = 0; i < 1000; ++i) {
    lucent::ref::BsdfSample s = b->sample(wo, (i + 0.5) / 1000, 0.3, 0.7);
    ASSERT_TRUE(s.valid);
    if (!s.delta) continue;
    ++deltas;
    const dvec3 mirror = 2 * glm::dot(wo, sp.n) * sp.n - wo;
    EXPECT_NEAR(glm::length(s.wi - mirror), 0, 1e-12);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(s.weight[c], 2 * m.specular[c], 1e-12);
  }
  EXPECT_EQ(deltas, 500);
}

// Rough dielectric (GGX reflection and transmission, Walter et al. 2007): both hemispheres,
// from outside (eta = 1.5) and inside (eta = 1 / 1.5; at 0.9 rad, beyond the critical angle of
// 0.73 rad, most microfacets reflect everything), three roughnesses. 64 x 64 cells over the
// sphere (2^19 samples) for the narrow lobes of roughness 0.1.
lucent::Material rough_glass(double roughness) {
  lucent::Material m;
  m.type = MaterialType::RoughDielectric;
  m.specular = dvec3(1.0, 0.8, 0.6);
  m.ior = 1.5;
  m.roughness = roughness;
  return m;
}

TEST(ReferenceSampling, BsdfRoughDielectricOutside) {
  chi_square_bsdf("rough dielectric 0.1 outside", rough_glass(0.1), 0.6, true, -1, 64, 64, 1 << 19);
  chi_square_bsdf("rough dielectric 0.3 outside", rough_glass(0.3), 1.2, true, -1, 32, 32);
  chi_square_bsdf("rough dielectric 0.7 outside", rough_glass(0.7), 0.3, true, -1, 32, 32);
}

TEST(ReferenceSampling, BsdfRoughDielectricInside) {
  chi_square_bsdf("rough dielectric 0.1 inside", rough_glass(0.1), 0.5, false, -1, 64, 64, 1 << 19);
  chi_square_bsdf("rough dielectric 0.3 inside", rough_glass(0.3), 0.9, false, -1, 32, 32);
  chi_square_bsdf("rough dielectric 0.7 inside", rough_glass(0.7), 1.3, false, -1, 32, 32);
}

// ------------------------------------------------------------------------------------------
// lights

// Distances t > 0 at which the ray (o, d) meets primitive `prim`, with the front normal there.
void prim_hits(const lucent::ref::World& w, int prim, const dvec3& o, const dvec3& d,
               std::vector<std::pair<double, dvec3>>& hits) {
  hits.clear();
  const lucent::ref::Prim& p = w.prims[prim];
  if (p.shape == lucent::ref::Shape::Sphere) {
    const lucent::Sphere& s = w.scene.spheres[p.index];
    dvec3 oc = o - s.center;
    double bh = glm::dot(oc, d), c = glm::dot(oc, oc) - s.radius * s.radius;
    double disc = bh * bh - c;
    if (disc < 0) return;
    for (double t : {-bh - std::sqrt(disc), -bh + std::sqrt(disc)})
      if (t > 0) hits.push_back({t, (o + t * d - s.center) / s.radius});
    return;
  }
  const lucent::Triangle& tr = w.scene.triangles[p.index];
  const dvec3 &v0 = w.scene.positions[tr.v[0]], &v1 = w.scene.positions[tr.v[1]],
              &v2 = w.scene.positions[tr.v[2]];
  dvec3 e1 = v1 - v0, e2 = v2 - v0, pv = glm::cross(d, e2);
  double det = glm::dot(e1, pv);
  if (std::abs(det) < 1e-15) return;
  dvec3 tv = o - v0;
  double u = glm::dot(tv, pv) / det;
  dvec3 qv = glm::cross(tv, e1);
  double v = glm::dot(d, qv) / det, t = glm::dot(e2, qv) / det;
  if (u < 0 || v < 0 || u + v > 1 || t <= 0) return;
  hits.push_back({t, glm::normalize(glm::cross(e1, e2))});
}

// Samples next-event estimation's directions from the origin and bins them over the whole
// sphere (48 x 96 cells; the lights sit near the equator). The density of a direction is the
// sum over the light list of: the environment's Light::pdf, and the area lights' Light::pdf
// (Lights::pdf_hit) at every point where the ray meets an area light's primitive from its front
// side (the test's own ray intersection). Point lights are delta: their samples count as
// unsuccessful. Also: a sample's reported pdf equals that density (one light), or is at most it
// (several).
//
// Expected counts: the environment and triangle terms are integrated over directions
// (chi_square's quadrature). A sphere's term grows like 1 / cos_l towards its silhouette, an
// integrable singularity that a midpoint rule over directions gets wrong by several percent in
// the silhouette's cells; it is integrated over the sphere's surface instead, where
// pdf dw = area_light_pdf(y) cos_l / dist^2 dA is smooth: a 2048 x 2048 grid, uniform in area
// (z, phi), each point's value added to the cell of its direction.
void chi_square_lights(const std::string& json, const char* name, bool single_light = true,
                       int N = 1 << 18) {
  lucent::Scene scene = lucent::parse_scene(json, lucent::test::temp_dir() + "/lights.json");
  lucent::ref::World world(scene);
  lucent::ref::Lights lights(world);
  ASSERT_FALSE(lights.empty());
  auto is_sphere = [&](int prim) { return world.prims[prim].shape == lucent::ref::Shape::Sphere; };
  const dvec3 p(0.0);
  const int NT = 48, NP = 96;
  std::vector<std::pair<double, dvec3>> hits;
  auto pdf_terms = [&](const dvec3& wi, bool spheres) {
    double sum = 0;
    if (lights.environment()) sum += lights.environment()->pdf(wi, lucent::ref::kInf, 0);
    for (int prim = 0; prim < static_cast<int>(world.prims.size()); ++prim) {
      if (!lights.area_light(prim) || (is_sphere(prim) && !spheres)) continue;
      prim_hits(world, prim, p, wi, hits);
      for (auto& h : hits) sum += lights.pdf_hit(prim, wi, h.first, -glm::dot(h.second, wi));
    }
    return sum;
  };
  auto pdf = [&](const dvec3& wi) { return pdf_terms(wi, true); };
  auto pdf_no_spheres = [&](const dvec3& wi) { return pdf_terms(wi, false); };
  auto sphere_terms = [&](int N, std::vector<double>& expected) {
    const int M = 2048;
    for (int prim = 0; prim < static_cast<int>(world.prims.size()); ++prim) {
      if (!lights.area_light(prim) || !is_sphere(prim)) continue;
      const lucent::Sphere& sp = scene.spheres[world.prims[prim].index];
      const double dA = sp.radius * sp.radius * (2.0 / M) * (2 * kPi / M);
      for (int i = 0; i < M; ++i)
        for (int j = 0; j < M; ++j) {
          double z = -1 + 2 * (i + 0.5) / M, phi = 2 * kPi * (j + 0.5) / M;
          double r = std::sqrt(std::max(0.0, 1 - z * z));
          dvec3 n(r * std::cos(phi), r * std::sin(phi), z), y = sp.center + sp.radius * n;
          double dist = glm::length(y - p);
          dvec3 wi = (y - p) / dist;
          double cos_l = -glm::dot(n, wi);
          if (cos_l <= 0) continue;
          double pw = lights.pdf_hit(prim, wi, dist, cos_l);
          int ti = std::min(NT - 1, int((std::clamp(wi.z, -1.0, 1.0) + 1) / 2 * NT));
          double ph = std::atan2(wi.y, wi.x);
          if (ph < 0) ph += 2 * kPi;
          int pi = std::min(NP - 1, int(ph / (2 * kPi) * NP));
          expected[ti * NP + pi] += pw * cos_l / (dist * dist) * dA * N;
        }
    }
  };
  int checked = 0;
  auto sample = [&](std::mt19937_64& rng, dvec3& w) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    double a = u(rng), b1 = u(rng), b2 = u(rng);
    lucent::ref::LightSample s = lights.sample(p, a, b1, b2);
    if (!s.valid || s.delta) return false;
    w = s.wi;
    if (checked < 4000) {
      ++checked;
      double want = pdf(s.wi);
      if (single_light)
        EXPECT_NEAR(s.pdf, want, 1e-6 * want) << name;
      else
        EXPECT_LE(s.pdf, want * (1 + 1e-6)) << name;
    }
    return true;
  };
  chi_square(name, Frame{dvec3(1, 0, 0), dvec3(0, 1, 0), dvec3(0, 0, 1)}, -1.0, NT, NP, sample,
             pdf_no_spheres, 0x5eed1000u + json.size(), sphere_terms, N);
}

const char* kMats = R"("materials": {
    "lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [2, 3, 4]},
    "dim": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [0.5, 0.5, 0.5]}})";

TEST(ReferenceSampling, SphereLightByArea) {
  chi_square_lights(std::string("{") + kMats + R"(, "shapes": [
      {"type": "sphere", "center": [2, 0.3, 0.2], "radius": 0.5, "material": "lamp"}]})",
                    "sphere, small");
}

// Only ~9% of the sphere's area faces the point: 2^20 samples for ~2^17 successful ones.
TEST(ReferenceSampling, SphereLightNear) {
  chi_square_lights(std::string("{") + kMats + R"(, "shapes": [
      {"type": "sphere", "center": [0.1, 0.7, -0.2], "radius": 0.6, "material": "lamp"}]})",
                    "sphere, near", true, 1 << 20);
}

TEST(ReferenceSampling, TriangleLightsByArea) {
  chi_square_lights(std::string("{") + kMats + R"(, "shapes": [
      {"type": "triangles", "material": "lamp",
       "positions": [[1, -1, -0.5], [1.5, 1, -0.8], [0.8, 0.2, 1], [1.1, -1.2, 1]],
       "indices": [0, 2, 1, 0, 3, 2]}]})",
                    "triangles");
}

// The reference samples an environment map uniformly over the sphere, whatever its texels.
TEST(ReferenceSampling, EnvironmentMap) {
  std::string dir = lucent::test::temp_dir();
  lucent::Image img{24, 12, std::vector<float>(24 * 12 * 3)};
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 24; ++x)
      for (int c = 0; c < 3; ++c)
        img.pixel(x, y)[c] =
            float(0.05 + ((x * 7 + y * 3) % 11) * 0.3 + (x == 5 && y == 3 ? 40 : 0));
  lucent::write_image(dir + "/env.pfm", img);
  chi_square_lights(R"({"lights": [{"type": "environment", "file": ")" + dir + R"(/env.pfm"}]})",
                    "environment map");
}

// Uniform choice among six lights: the environment, a point light (delta: its samples count as
// failures), three spheres (two of them overlap as seen from the origin, so their densities add)
// and a triangle that faces away from the origin (all its samples fail).
TEST(ReferenceSampling, UniformMixture) {
  chi_square_lights(std::string("{") + kMats + R"(, "shapes": [
      {"type": "sphere", "center": [2, 0.3, 0.2], "radius": 0.5, "material": "lamp"},
      {"type": "sphere", "center": [-1, 1.5, -0.2], "radius": 0.3, "material": "dim"},
      {"type": "sphere", "center": [3.5, 0.5, 0.3], "radius": 0.6, "material": "dim"},
      {"type": "triangles", "material": "lamp",
       "positions": [[-1, -2, -1], [1, -2, -1], [0, -2, 1]], "indices": [0, 1, 2]}],
    "lights": [{"type": "environment", "radiance": [0.2, 0.2, 0.2]},
               {"type": "point", "position": [0, 0, 3], "intensity": [1, 1, 1]}]})",
                    "mixture", false);
}

}  // namespace

}  // namespace test_reference_sampling
