// The reference's pixel filters, one function per entry of LC_FILTER_TYPES (filter_<file>), each
// drawing the offset from the filter's density by its own method (the kernel uses others: the
// same densities, different numbers); filter_offset dispatches through the registry.
#include <cmath>

#include "reference/camera/camera.hpp"

namespace lucent::ref {

namespace {

/// box, radius r: dx, dy uniform on [-r, r].
dvec2 filter_box(double r, const Sampler& rng) {
  return dvec2((2 * rng.get(LC_DIM_FILTER) - 1) * r, (2 * rng.get(LC_DIM_FILTER + 1) - 1) * r);
}

/// tent, radius r: the sum of two uniforms on [0, r] minus r has density (r - |t|) / r^2 on
/// [-r, r].
dvec2 filter_tent(double r, const Sampler& rng) {
  return dvec2(r * (rng.get(LC_DIM_FILTER) + rng.get(kDimExtra) - 1),
               r * (rng.get(LC_DIM_FILTER + 1) + rng.get(kDimExtra + 1) - 1));
}

/// gaussian, radius r: a 2D normal (Box-Muller) with sigma = r / 3, rejected outside the disk of
/// radius r.
dvec2 filter_gaussian(double r, const Sampler& rng) {
  double sigma = r / 3;
  for (std::uint32_t k = 0; k < 64; ++k) {
    double u1 = k == 0 ? rng.get(LC_DIM_FILTER) : rng.get(kDimExtra + 2 * k);
    double u2 = k == 0 ? rng.get(LC_DIM_FILTER + 1) : rng.get(kDimExtra + 2 * k + 1);
    double rho = sigma * std::sqrt(-2 * std::log(1 - u1)), phi = 2 * kPi * u2;
    if (rho <= r) return dvec2(rho * std::cos(phi), rho * std::sin(phi));
  }
  return dvec2(0.0);  // (0.011)^64: never
}

/// The densities of the three filters (docs/rendering-model.md, "Camera and film"), each written
/// next to its sampling above.
double density_box(double r, dvec2 o) {
  return std::abs(o.x) <= r && std::abs(o.y) <= r ? 1 / (4 * r * r) : 0;
}

double density_tent(double r, dvec2 o) {
  auto d = [r](double t) { return std::abs(t) <= r ? (r - std::abs(t)) / (r * r) : 0.0; };
  return d(o.x) * d(o.y);
}

/// exp(-rho^2 / (2 sigma^2)) on the disk rho <= r, over its integral there,
/// 2 pi sigma^2 (1 - exp(-r^2 / (2 sigma^2))).
double density_gaussian(double r, dvec2 o) {
  double sigma = r / 3, rho2 = glm::dot(o, o);
  if (rho2 > r * r) return 0;
  double k = 1 / (2 * sigma * sigma);
  return std::exp(-rho2 * k) / (2 * kPi * sigma * sigma * (1 - std::exp(-r * r * k)));
}

}  // namespace

double filter_density(const Filter& filter, dvec2 offset) {
  switch (filter.type) {
#define LUCENT_REF_FILTER_DENSITY(ID, Name, value, name, feature, file, ...) \
  case FilterType::Name:                                                     \
    return density_##file(filter.radius, offset);
    LC_FILTER_TYPES(LUCENT_REF_FILTER_DENSITY)
#undef LUCENT_REF_FILTER_DENSITY
  }
  return 0;
}

dvec2 filter_offset(const Filter& filter, const Sampler& rng) {
  switch (filter.type) {
#define LUCENT_REF_FILTER_CASE(ID, Name, value, name, feature, file, ...) \
  case FilterType::Name:                                                  \
    return filter_##file(filter.radius, rng);
    LC_FILTER_TYPES(LUCENT_REF_FILTER_CASE)
#undef LUCENT_REF_FILTER_CASE
  }
  return dvec2(0.0);
}

}  // namespace lucent::ref
