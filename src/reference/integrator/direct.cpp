// direct: the emitted radiance at the first hit plus point-light illumination through the full
// BSDF (delta BSDFs receive none). A debugging and first-light integrator.
#include "reference/integrator/integrator.hpp"

namespace lucent::ref {

dvec3 integrator_direct(const Tracer& t, const Ray& ray, const Sampler&) {
  Hit hit;
  if (!t.trace(ray, hit)) return t.escaped(ray.d);
  Surface s = t.surface(ray, hit);
  std::unique_ptr<Bsdf> b = t.bsdf(s);
  const dvec3 wo = -ray.d;
  dvec3 sum(0.0);
  for (std::size_t i = 0; i < t.lights.size(); ++i)
    if (t.lights[i].is_delta()) sum += t.delta_light(s, *b, wo, t.lights[i].sample(s.p, 0, 0));
  return t.emitted(s) + sum;
}

}  // namespace lucent::ref
