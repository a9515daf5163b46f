// The light table: the scene's point and environment lights after the area lights of emissive
// shapes, each light's selection probability (90% by power, 10% uniform) and the light_cdf buffer
// (selection CDF, then every environment map's texel CDF). kernels/light/ samples from them.
#include <algorithm>
#include <cmath>

#include "lucent/error.hpp"
#include "render/pack.hpp"
#include "scene/material_type.hpp"
#include "scene/validate.hpp"

namespace lucent::render_detail {

namespace {

using scene_detail::put3;

/// The kernel draws its numbers on the lattice k / 2^24 (lc_u01) and lc_cdf_search takes the
/// first entry i with u < cdf[i]. A CDF whose entries lie on that lattice gives each interval
/// exactly the probability the kernel divides by, the difference of its two ends: rounded to
/// floats on their own, the two differ by up to 2^-24, which is 6% of a light's share among a
/// million lights or of a texel's among a 2048 x 1024 map's.
constexpr double kLattice = 16777216.0;  // 2^24

/// Appends the lattice CDF of the weights `w` (non-negative, summing to `total` > 0): entry i is
/// the running sum rounded to the lattice, kept non-decreasing; the last is 1.
void append_lattice_cdf(const std::vector<double>& w, double total, sys::HostVector<float>& cdf) {
  double run = 0;
  std::uint32_t prev = 0;
  for (size_t i = 0; i < w.size(); ++i) {
    run += w[i];
    std::uint32_t q = i + 1 == w.size()
                          ? std::uint32_t(kLattice)
                          : std::uint32_t(std::clamp(std::llround(run / total * kLattice),
                                                     (long long)prev, (long long)kLattice));
    cdf.push_back(static_cast<float>(q / kLattice));
    prev = q;
  }
}

}  // namespace

void append_selection_cdf(const std::vector<double>& w, sys::HostVector<float>& cdf) {
  const size_t start = cdf.size();
  append_lattice_cdf(w, 1.0, cdf);
  // a light whose interval rounded to nothing is never chosen: a point light is then never lit
  // (more than 2^24 / 10 lights, one of which holds the power: 2e6 dim point lights beside a
  // bright one lost 16% of their light without a word). Each then gets a lattice step at least,
  // taken from the largest intervals; unchanged where every light has one (the images of a seed).
  bool starved = false;
  for (size_t i = 0; i < w.size() && !starved; ++i)
    starved = w[i] > 0 && cdf[start + i] == (i ? cdf[start + i - 1] : 0.0f);
  if (!starved || w.size() > size_t(kLattice)) return;
  std::vector<long long> steps(w.size());
  long long sum = 0;
  for (size_t i = 0; i < w.size(); ++i) {
    steps[i] = w[i] > 0 ? std::max(1LL, static_cast<long long>(std::floor(w[i] * kLattice))) : 0;
    sum += steps[i];
  }
  std::vector<size_t> order(w.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&w](size_t a, size_t b) { return w[a] > w[b]; });
  long long diff = static_cast<long long>(kLattice) - sum;  // what the lattice still has to give
  for (size_t k = 0; diff != 0 && k < order.size(); ++k) {
    long long& n = steps[order[k]];
    if (diff > 0 && w[order[k]] > 0) {
      ++n;  // (the floors' deficit is below one step a light)
      --diff;
    } else if (diff < 0) {
      const long long take = std::min(n - 1, -diff);
      n -= take;
      diff += take;
    }
  }
  if (diff != 0) return;  // (near 2^24 lights, too few steps to take: the rounding stays)
  long long run = 0;
  for (size_t i = 0; i < w.size(); ++i) {
    run += steps[i];
    cdf[start + i] = static_cast<float>(double(run) / kLattice);
  }
}

namespace {

/// The texel CDF of an environment map (luminance x sin(theta), n + 1 entries from 0 to 1, on
/// the lattice), appended to `cdf`. A texel whose share is below a lattice step may get
/// none: light sampling then never picks it, its pdf is 0, and BSDF sampling alone covers it.
void append_env_map_cdf(const Texture& t, sys::HostVector<float>& cdf) {
  std::vector<double> w(static_cast<size_t>(t.width) * t.height);
  double total_w = 0;
  for (int y = 0; y < t.height; ++y) {
    double sin_t = std::sin(M_PI * (y + 0.5) / t.height);
    for (int x = 0; x < t.width; ++x) {
      const float* px = &t.rgba[(static_cast<size_t>(y) * t.width + x) * 4];
      double lum = std::max(0.0, luminance({px[0], px[1], px[2]}));
      w[static_cast<size_t>(y) * t.width + x] = lum * sin_t;
      total_w += lum * sin_t;
    }
  }
  if (!(total_w > 0)) std::fill(w.begin(), w.end(), 1.0), total_w = double(w.size());
  cdf.push_back(0.0f);
  append_lattice_cdf(w, total_w, cdf);
}

}  // namespace

double environment_radius(const Camera& camera, const PackedScene& p) {
  // Radius of the region that matters, for the power of environment lights: the scene's
  // bounding radius, but no more than the camera's distance to what it looks at (a ground sphere
  // of radius 1000 would otherwise make the sky outweigh every point light a thousandfold).
  // Selection probabilities change only the variance, never the expected value.
  double radius = 1;
  if (!p.nodes.empty()) {
    const float *lo = p.bounds_min, *hi = p.bounds_max;
    glm::dvec3 d(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    radius = std::max(1e-6, 0.5 * glm::length(d));
  }
  double view = glm::length(camera.look_at - camera.position);
  if (view > 0 && std::isfinite(view)) radius = std::min(radius, view);
  return radius;
}

void pack_lights(const Scene& scene, PackedScene& p, std::vector<double> power, double radius) {
  for (const Light& l : scene.lights) {
    lc_light d{};
    d.type = static_cast<lc_uint>(l.type);
    double pw = 0;
    switch (l.type) {
      case LightType::Point:
        put3(d.p.point.position, l.position);
        put3(d.p.point.intensity, l.intensity);
        pw = luminance(l.intensity) * 4 * M_PI;
        break;
      case LightType::Environment:
        put3(d.p.env.radiance, l.radiance);
        break;
      case LightType::EnvironmentMap:
        put3(d.p.env_map.scale, l.radiance);
        d.p.env_map.texture = l.texture;
        d.p.env_map.cdf = LC_INVALID;  // below, after the selection CDF
        break;
      default:
        throw Error(scene_detail::in_file(scene.path, "a scene light cannot be of type " +
                                                          std::to_string(static_cast<int>(l.type)) +
                                                          " (area lights are emissive shapes)"));
    }
    if (l.type == LightType::Environment || l.type == LightType::EnvironmentMap) {
      pw = luminance(l.radiance) * M_PI * 4 * M_PI * radius * radius;
      p.params.env_light = static_cast<lc_int>(p.lights.size());
    }
    p.lights.push_back(d);
    power.push_back(std::max(0.0, pw));
  }
  double total = 0;
  for (double w : power) total += w;
  // 90% by power, 10% uniform: a defensive mixture, so that no light starves when one power
  // estimate dwarfs the others (an environment behind a 1000-unit floor sphere). On the lattice,
  // pdf_select is exactly each light's interval of the CDF.
  std::vector<double> select(p.lights.size());
  for (size_t i = 0; i < p.lights.size(); ++i) {
    double uniform = 1.0 / p.lights.size();
    select[i] = total > 0 ? 0.9 * power[i] / total + 0.1 * uniform : uniform;
  }
  if (!select.empty()) append_selection_cdf(select, p.light_cdf);
  for (size_t i = 0; i < p.lights.size(); ++i)
    p.lights[i].pdf_select = p.light_cdf[i] - (i ? p.light_cdf[i - 1] : 0.0f);

  for (lc_light& l : p.lights) {
    if (l.type != LC_LIGHT_ENV_MAP) continue;
    l.p.env_map.cdf = static_cast<lc_uint>(p.light_cdf.size());
    append_env_map_cdf(scene.textures.at(static_cast<size_t>(l.p.env_map.texture)), p.light_cdf);
  }
}

}  // namespace lucent::render_detail
