#pragma once
// The reference's integrators (docs/rendering-model.md, "Integrators"): one function per entry of
// LC_INTEGRATOR_TYPES, integrator_<file>() in integrator/<file>.cpp, and one per AOV of
// LC_AOV_TYPES, aov_<file>() in integrator/aov.cpp; radiance() dispatches through the registries.
// They see the scene through a Tracer.
#include <cstdint>
#include <memory>

#include "reference/bsdf/bsdf.hpp"
#include "reference/common.hpp"
#include "reference/geometry/world.hpp"
#include "reference/light/light.hpp"
#include "reference/sampler.hpp"

namespace lucent::ref {

/// The scene as the integrators see it: geometry, lights, and the queries they share. Rays
/// traced are counted per thread (ray_count).
class Tracer {
 public:
  explicit Tracer(const Scene& s) : scene(s), world(s), lights(world) {}

  const Scene& scene;
  World world;
  Lights lights;

  /// Closest hit, ignoring primitive `skip` (if >= 0).
  bool trace(const Ray& r, Hit& h, int skip = -1) const;
  bool blocked(const Ray& r, double tmax, int skip = -1) const;
  Surface surface(const Ray& r, const Hit& h) const { return world.surface(r, h); }

  /// A ray leaving surface s in direction wi, from the side of the surface that wi points to.
  static Ray spawn(const Surface& s, const dvec3& wi) {
    double side = glm::dot(wi, s.ng) > 0 ? 1 : -1;
    return Ray{s.p + side * s.err * s.ng, wi};
  }

  /// Radiance of a ray that leaves the scene in direction d.
  dvec3 escaped(const dvec3& d) const {
    const Light* env = lights.environment();
    return env ? env->radiance(d) : dvec3(0.0);
  }
  /// Emitted radiance towards the ray that hit s: the material's emission on the front side.
  dvec3 emitted(const Surface& s) const {
    return s.front ? scene.materials[s.material].emission : dvec3(0.0);
  }
  std::unique_ptr<Bsdf> bsdf(const Surface& s) const {
    return make_bsdf(scene, scene.materials[s.material], ShadingPoint{s.ns, s.ng, s.uv, s.front});
  }

  /// Is the light's sampled point visible from s? (A shadow ray from the side wi points to.)
  bool visible(const Surface& s, const LightSample& ls) const;
  /// Light from a delta (point) light sample through BSDF b: f I / r^2, 0 when shadowed.
  dvec3 delta_light(const Surface& s, const Bsdf& b, const dvec3& wo, const LightSample& ls) const;
};

/// Rays traced by the calling thread since the last reset.
std::uint64_t ray_count();
void reset_ray_count();

/// The value of one camera ray for the scene's integrator or AOV.
dvec3 radiance(const Tracer& t, const Ray& ray, const Sampler& rng);

#define LUCENT_REF_DECLARE_INTEGRATOR(ID, Name, value, name, feature, file) \
  dvec3 integrator_##file(const Tracer& t, const Ray& ray, const Sampler& rng);
LC_INTEGRATOR_TYPES(LUCENT_REF_DECLARE_INTEGRATOR)
#undef LUCENT_REF_DECLARE_INTEGRATOR

/// AOVs: the value at the first hit (hit, s) of the camera ray (0 on a miss, handled by radiance).
#define LUCENT_REF_DECLARE_AOV(ID, Name, value, name, feature, file)                  \
  dvec3 aov_##file(const Tracer& t, const Ray& ray, const Hit& hit, const Surface& s, \
                   const Sampler& rng);
LC_AOV_TYPES(LUCENT_REF_DECLARE_AOV)
#undef LUCENT_REF_DECLARE_AOV

}  // namespace lucent::ref
