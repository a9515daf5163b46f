// whitted: deterministic classic ray tracing. At each hit: the emitted radiance plus what the
// BSDF's Whitted lobes (Bsdf::whitted) say: a diffuse part lit by the point lights through shadow
// rays, a reflected and a transmitted ray with deterministic weights. Recursion stops after
// max_depth segments; escaping rays return the environment radiance; area lights contribute only
// where seen.
#include <vector>

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

/// A ray still to trace, with the weight its radiance has in the pixel.
struct Branch {
  Ray ray;
  int depth;  // segments before this ray
  dvec3 throughput;
};

}  // namespace

// The recursion L = emitted + diffuse + w_r L(reflected) + w_t L(refracted), unrolled into a list
// of pending branches: a chain of 100000 mirror bounces (two parallel mirrors at max_depth 100000)
// overflowed the thread's stack when this recursed.
dvec3 integrator_whitted(const Tracer& t, const Ray& ray, const Sampler&) {
  dvec3 L(0.0);
  std::vector<Branch> pending{Branch{ray, 0, dvec3(1.0)}};
  while (!pending.empty()) {
    const Branch b = pending.back();
    pending.pop_back();
    Hit hit;
    if (!t.trace(b.ray, hit)) {
      L += b.throughput * t.escaped(b.ray.d);
      continue;
    }
    Surface s = t.surface(b.ray, hit);
    L += b.throughput * t.emitted(s);
    if (b.depth + 1 >= t.scene.integrator.max_depth) continue;
    // branches too faint to matter are cut (the only departure from the exact recursion)
    if (max3(b.throughput) < 1e-9) continue;
    WhittedLobes lobes = t.bsdf(s)->whitted(-b.ray.d);
    if (lobes.diffuse) L += b.throughput * diffuse_term(t, s, lobes.albedo);
    if (lobes.reflect)
      pending.push_back(Branch{Tracer::spawn(s, lobes.reflect_dir), b.depth + 1,
                               b.throughput * lobes.reflect_weight});
    if (lobes.transmit)
      pending.push_back(Branch{Tracer::spawn(s, lobes.transmit_dir), b.depth + 1,
                               b.throughput * lobes.transmit_weight});
  }
  return L;
}

}  // namespace lucent::ref
