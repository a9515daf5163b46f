// path: unidirectional path tracing with next-event estimation at every non-delta vertex, one
// light chosen uniformly, and multiple importance sampling (power heuristic) between light and
// BSDF sampling. Expected value: the rendering equation truncated at max_depth segments (with
// integrator.clamp, the expectation of the clamped estimator: docs/rendering-model.md). With
// integrator.caustics, without the caustic paths E N (N|S)* S L that the light tracer renders.
#include <algorithm>
#include <cfloat>
#include <cmath>

#include "reference/integrator/integrator.hpp"

namespace lucent::ref {

namespace {

double power_heuristic(double a, double b) {
  if (std::isinf(a)) return 1;
  return a * a / (a * a + b * b);
}

/// Next-event estimation at s: one light chosen uniformly, MIS-weighted against BSDF sampling;
/// delta lights get no MIS. Light sampled through the surface is fine: the shadow ray leaves
/// from the side the light is on, and b.eval says how much of it the BSDF transmits.
dvec3 next_event(const Tracer& t, const Surface& s, const Bsdf& b, const dvec3& wo,
                 const Sampler& rng, int depth) {
  if (t.lights.empty()) return dvec3(0.0);
  LightSample ls =
      t.lights.sample(s.p, rng.bounce(depth, LC_DIM_LIGHT_SELECT),
                      rng.bounce(depth, LC_DIM_LIGHT_UV), rng.bounce(depth, LC_DIM_LIGHT_UV + 1));
  // a delta light's pdf is its selection probability 1 / size
  if (ls.delta) return static_cast<double>(t.lights.size()) * t.delta_light(s, b, wo, ls);
  if (!ls.valid) return dvec3(0.0);
  dvec3 f = b.eval(wo, ls.wi);
  if (max3(f) <= 0 || max3(ls.Le) <= 0) return dvec3(0.0);
  if (!t.visible(s, ls)) return dvec3(0.0);
  return f * ls.Le * power_heuristic(ls.pdf, b.pdf(wo, ls.wi)) / ls.pdf;
}

/// integrator.clamp: a contribution after a scattering whose largest component exceeds `bound`
/// (> 0) is scaled down to it; non-finite ones stay non-finite.
dvec3 clamped(const dvec3& c, double bound) {
  double m = std::max({c.x, c.y, c.z});
  return bound > 0 && m > bound ? c * (bound / m) : c;
}

}  // namespace

dvec3 integrator_path(const Tracer& t, const Ray& camera_ray, const Sampler& rng) {
  const Integrator& in = t.scene.integrator;
  // the kernel clamps against the bound rounded to float (render/pack.cpp)
  const double bound = in.clamp > 0 ? std::max<double>(static_cast<float>(in.clamp), FLT_MIN) : 0;
  const Light* env = t.lights.environment();
  Ray ray = camera_ray;
  dvec3 L(0.0), beta(1.0);
  double prev_pdf = 0;     // BSDF pdf of the previous direction
  bool prev_delta = true;  // camera rays and delta bounces: no MIS on what they hit
  // integrator.caustics: a caustic path, E N (N|S)* S L, samples a non-delta lobe at the first
  // hit and a delta one at the vertex before the emitter; the light tracer renders those
  // (integrator/light_tracer.cpp). first_nondelta: the lobe sampled at the first hit.
  bool first_nondelta = false;
  for (int depth = 0;; ++depth) {
    Hit hit;
    if (!t.trace(ray, hit)) {
      double w = 1;
      if (!prev_delta && env) w = power_heuristic(prev_pdf, env->pdf(ray.d, kInf, 0));
      dvec3 c = beta * t.escaped(ray.d) * w;
      L += depth > 0 ? clamped(c, bound) : c;
      break;
    }
    Surface s = t.surface(ray, hit);
    dvec3 Le = t.emitted(s);
    const bool caustic = in.caustics && first_nondelta && prev_delta;
    if (max3(Le) > 0 && !caustic) {
      double w = 1;
      if (!prev_delta)
        w = power_heuristic(prev_pdf,
                            t.lights.pdf_hit(s.prim, ray.d, hit.t, glm::dot(s.ng, -ray.d)));
      L += depth > 0 ? clamped(beta * Le * w, bound) : beta * Le * w;
    }
    if (depth + 1 >= in.max_depth) break;
    dvec3 wo = -ray.d;
    std::unique_ptr<Bsdf> b = t.bsdf(s);
    if (!b->is_delta()) L += clamped(beta * next_event(t, s, *b, wo, rng, depth), bound);
    BsdfSample bs =
        b->sample(wo, rng.bounce(depth, LC_DIM_BSDF_LOBE), rng.bounce(depth, LC_DIM_BSDF_UV),
                  rng.bounce(depth, LC_DIM_BSDF_UV + 1));
    if (!bs.valid) break;
    beta *= bs.weight;
    prev_pdf = bs.pdf;
    prev_delta = bs.delta;
    if (depth == 0) first_nondelta = !bs.delta;
    ray = Tracer::spawn(s, bs.wi);
    // Russian roulette once the path has rr_depth segments: while the largest component of the
    // throughput is below 1 the path survives with that probability and the throughput is
    // divided by it, so it never exceeds 1 (a cap such as min(0.95, max(beta)) lets beta grow
    // like (albedo / 0.95)^n above albedo 0.95: unbiased, but of infinite variance).
    double q = max3(beta);
    if (depth + 1 >= in.rr_depth && q < 1) {
      if (rng.bounce(depth, LC_DIM_RR) >= q) break;
      beta /= q;
    }
  }
  return L;
}

}  // namespace lucent::ref
