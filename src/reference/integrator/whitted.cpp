// whitted: deterministic classic ray tracing. At each hit: the emitted radiance plus what the
// BSDF's Whitted lobes (Bsdf::whitted) say: a diffuse part lit by the point lights through shadow
// rays, a reflected and a transmitted ray with deterministic weights. Recursion stops after
// max_depth segments; escaping rays return the environment radiance; area lights contribute only
// where seen.
#include "reference/integrator/integrator.hpp"

namespace lucent::ref {

namespace {

/// albedo / pi * sum over the point lights of I cos / r^2 (shadow rays).
dvec3 diffuse_term(const Tracer& t, const Surface& s, const dvec3& albedo) {
  dvec3 sum(0.0);
  for (std::size_t i = 0; i < t.lights.size(); ++i) {
    if (!t.lights[i].is_delta()) continue;
    LightSample ls = t.lights[i].sample(s.p, 0, 0);
    if (!ls.valid) continue;
    double c = glm::dot(ls.wi, s.ns);
    if (c <= 0 || glm::dot(ls.wi, s.ng) <= 0) continue;
    if (!t.visible(s, ls)) continue;
    sum += ls.Le * c / ls.dist2;
  }
  return albedo / kPi * sum;
}

dvec3 whitted(const Tracer& t, const Ray& ray, int depth, const dvec3& throughput) {
  Hit hit;
  if (!t.trace(ray, hit)) return t.escaped(ray.d);
  Surface s = t.surface(ray, hit);
  dvec3 L = t.emitted(s);
  if (depth + 1 >= t.scene.integrator.max_depth) return L;
  // branches too faint to matter are cut (the only departure from the exact recursion)
  if (max3(throughput) < 1e-9) return L;
  WhittedLobes lobes = t.bsdf(s)->whitted(-ray.d);
  if (lobes.diffuse) L += diffuse_term(t, s, lobes.albedo);
  if (lobes.reflect) {
    const dvec3& w = lobes.reflect_weight;
    L += w * whitted(t, Tracer::spawn(s, lobes.reflect_dir), depth + 1, throughput * w);
  }
  if (lobes.transmit) {
    const dvec3& w = lobes.transmit_weight;
    L += w * whitted(t, Tracer::spawn(s, lobes.transmit_dir), depth + 1, throughput * w);
  }
  return L;
}

}  // namespace

dvec3 integrator_whitted(const Tracer& t, const Ray& ray, const Sampler&) {
  return whitted(t, ray, 0, dvec3(1.0));
}

}  // namespace lucent::ref
