// The reference's integrator dispatch (generated from LC_INTEGRATOR_TYPES and LC_AOV_TYPES) and
// the scene queries the integrators share.
#include "reference/integrator/integrator.hpp"

namespace lucent::ref {

namespace {

/// Rays traced by the calling thread.
thread_local std::uint64_t t_rays = 0;

}  // namespace

std::uint64_t ray_count() { return t_rays; }
void reset_ray_count() { t_rays = 0; }

bool Tracer::trace(const Ray& r, Hit& h, int skip) const {
  ++t_rays;
  return world.intersect(r, kInf, h, skip);
}

bool Tracer::blocked(const Ray& r, double tmax, int skip) const {
  ++t_rays;
  return world.occluded(r, tmax, skip);
}

bool Tracer::visible(const Surface& s, const LightSample& ls) const {
  Ray r = spawn(s, ls.wi);
  double tmax = ls.dist >= kInf ? kInf : glm::length(ls.y - r.o) * (1 - ls.shadow_short);
  return !blocked(r, tmax, ls.skip);
}

dvec3 Tracer::delta_light(const Surface& s, const Bsdf& b, const dvec3& wo,
                          const LightSample& ls) const {
  if (!ls.valid) return dvec3(0.0);
  dvec3 f = b.eval(wo, ls.wi);
  if (max3(f) <= 0) return dvec3(0.0);
  if (!visible(s, ls)) return dvec3(0.0);
  return f * ls.Le / ls.dist2;
}

dvec3 radiance(const Tracer& t, const Ray& ray, const Sampler& rng) {
  switch (t.scene.integrator.type) {
#define LUCENT_REF_INTEGRATOR_CASE(ID, Name, value, name, feature, file) \
  case IntegratorType::Name:                                             \
    return integrator_##file(t, ray, rng);
    LC_INTEGRATOR_TYPES(LUCENT_REF_INTEGRATOR_CASE)
#undef LUCENT_REF_INTEGRATOR_CASE
    default:
      break;
  }
  Hit hit;
  if (!t.trace(ray, hit)) return dvec3(0.0);
  Surface s = t.surface(ray, hit);
  switch (t.scene.integrator.type) {
#define LUCENT_REF_AOV_CASE(ID, Name, value, name, feature, file) \
  case IntegratorType::Name:                                      \
    return aov_##file(t, ray, hit, s, rng);
    LC_AOV_TYPES(LUCENT_REF_AOV_CASE)
#undef LUCENT_REF_AOV_CASE
    default:
      break;
  }
  return dvec3(0.0);
}

}  // namespace lucent::ref
