#pragma once
// The reference integrator's vocabulary (src/reference/): double precision everywhere, plain
// structs, nothing shared with the kernel but the scene description (lucent/scene.hpp, its
// registries) and the random numbers (kernels/shared/rng.h).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>

#include "lucent/scene.hpp"

namespace lucent::ref {

using glm::dvec2;
using glm::dvec3;

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = 1e300;

struct Ray {
  dvec3 o;
  dvec3 d;  ///< unit length
};

inline double max3(const dvec3& v) { return glm::max(v.x, glm::max(v.y, v.z)); }

inline double max_abs(const dvec3& v) {
  return std::max(std::abs(v.x), std::max(std::abs(v.y), std::abs(v.z)));
}

/// v / |v| for any finite v other than 0 (0 stays 0), scaled first by the power of two of its
/// largest component: glm::normalize made [0, 1e-170, 0] NaN (its squared length underflows to
/// 0). The scaling is exact: where glm::normalize has no underflow, the same bits.
inline dvec3 unit(const dvec3& v) {
  double m = max_abs(v);
  if (!(m > 0) || !std::isfinite(m)) return v;
  int e = std::ilogb(m);
  return glm::normalize(dvec3(std::ldexp(v.x, -e), std::ldexp(v.y, -e), std::ldexp(v.z, -e)));
}

inline bool finite(const dvec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

/// Orthonormal t, b completing the unit vector n.
inline void basis(const dvec3& n, dvec3& t, dvec3& b) {
  dvec3 a = std::abs(n.x) > 0.5 ? dvec3(0, 1, 0) : dvec3(1, 0, 0);
  t = glm::normalize(glm::cross(a, n));
  b = glm::cross(n, t);
}

/// Cosine-distributed direction about the unit vector n (density cos / pi).
inline dvec3 cosine_direction(const dvec3& n, double u1, double u2) {
  dvec3 t, b;
  basis(n, t, b);
  double r = std::sqrt(u1), phi = 2 * kPi * u2;
  return glm::normalize(r * std::cos(phi) * t + r * std::sin(phi) * b +
                        std::sqrt(std::max(0.0, 1 - u1)) * n);
}

/// Uniformly distributed direction on the unit sphere (Archimedes: z uniform).
inline dvec3 uniform_sphere(double u1, double u2) {
  double z = 1 - 2 * u1, r = std::sqrt(std::max(0.0, 1 - z * z)), phi = 2 * kPi * u2;
  return dvec3(r * std::cos(phi), r * std::sin(phi), z);
}

}  // namespace lucent::ref
