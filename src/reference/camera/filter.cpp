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

}  // namespace

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
