// Caustics by light tracing, written from docs/rendering-model.md ("Caustics by light tracing"):
// a light chosen uniformly (Lights::emit), a point and direction from it (Light::emit),
// scatterings with the adjoint weight once the lobe sampled at y_1 was a delta one, a connection
// to the camera at every vertex y_i with a non-delta BSDF that the path reaches with i >= 2
// (paths E N (N|S)* S L), Russian roulette on the product of the adjoint weights.
#include "reference/integrator/light_tracer.hpp"

#include <cmath>

namespace lucent::ref {

namespace {

/// Number `offset` of light-path vertex i (0: the emission: +0,+1 point, +2 selection, +4,+5
/// direction; i >= 1: +0,+1 the lens point of its connection, +3 lobe, +4,+5 BSDF direction, +6
/// Russian roulette).
double light_dim(const Sampler& rng, int i, std::uint32_t offset) {
  return rng.get(LC_DIM_LIGHT_PATH + LC_DIMS_PER_BOUNCE * static_cast<std::uint32_t>(i) + offset);
}

}  // namespace

LightTracer::LightTracer(const Tracer& tracer, const CameraModel& camera)
    : t_(tracer), camera_(camera) {}

void LightTracer::trace(const Sampler& rng, std::vector<Splat>& out) const {
  const Integrator& in = t_.scene.integrator;
  // a connection at vertex y_i makes a camera path of i + 1 segments: at most max_depth
  const int max_vertices = in.max_depth - 1;
  if (max_vertices < 2) return;  // no caustic path fits
  LightEmission e = t_.lights.emit(light_dim(rng, 0, 2), light_dim(rng, 0, 0), light_dim(rng, 0, 1),
                                   light_dim(rng, 0, 4), light_dim(rng, 0, 5));
  if (!e.valid) return;
  dvec3 weight(1.0);  // product of the adjoint weights: beta = e.beta * weight
  Ray ray{e.y, e.d};
  int skip = e.skip;
  // The lobe sampled at y_1 was a delta one at every vertex the path reaches with i >= 2 (it ends
  // where it was not).
  for (int i = 1; i <= max_vertices; ++i) {
    Hit hit;
    if (!t_.trace(ray, hit, skip)) return;
    skip = -1;
    Surface s = t_.surface(ray, hit);
    std::unique_ptr<Bsdf> b = t_.bsdf(s);
    // A BSDF that is not wholly delta is connected through its non-delta part (eval); its delta
    // lobes, if any (diffuse_mirror's mirror), are sampled below like a delta BSDF's.
    if (i >= 2 && !b->is_delta())
      connect(ray, hit, e.beta * weight, light_dim(rng, i, 0), light_dim(rng, i, 1), out);
    if (i == max_vertices) return;
    const dvec3 wo = -ray.d;  // towards the arriving light
    BsdfSample bs =
        b->sample(wo, light_dim(rng, i, LC_DIM_BSDF_LOBE), light_dim(rng, i, LC_DIM_BSDF_UV),
                  light_dim(rng, i, LC_DIM_BSDF_UV + 1));
    if (!bs.valid) return;
    // a non-delta lobe at y_1 ends the path; after a delta one there, any lobe goes on
    if (i == 1 && !bs.delta) return;
    // The adjoint weight, for every lobe: the radiance weight without the 1 / eta^2 of
    // refraction (power is not compressed into a narrower cone as radiance is; bs.eta, delta or
    // rough), times the shading-normal correction |wo.ns| |wi.ng| / (|wo.ng| |wi.ns|) (Veach's
    // thesis, 5.3). The other BSDFs are symmetric: their weights are f |wi.ns| / pdf.
    const double corr = std::abs(glm::dot(wo, s.ns)) * std::abs(glm::dot(bs.wi, s.ng)) /
                        (std::abs(glm::dot(wo, s.ng)) * std::abs(glm::dot(bs.wi, s.ns)));
    weight *= bs.weight * (bs.eta * bs.eta) * corr;
    ray = Tracer::spawn(s, bs.wi);
    // Russian roulette from rr_depth vertices on, on the weight relative to the emission (the
    // power itself has units): survive with max(weight) while it is below 1.
    double q = max3(weight);
    if (i >= in.rr_depth && q < 1) {
      if (light_dim(rng, i, LC_DIM_RR) >= q) return;
      weight /= q;
    }
  }
}

void LightTracer::connect(const Ray& ray, const Hit& hit, const dvec3& beta, double lens_u,
                          double lens_v, std::vector<Splat>& out) const {
  const Surface sl = t_.surface(ray, hit);  // oriented towards the light ray
  const dvec3 x = sl.p;
  dvec2 film;
  double cos_c;
  dvec3 eye;  // the pinhole, or the point of the thin lens
  if (!camera_.project_lens(x, lens_u, lens_v, film, cos_c, eye)) return;
  const Filter& filter = camera_.filter();
  const int W = camera_.width(), H = camera_.height();
  const double fr = filter.radius;
  // no pixel's filter reaches film (this also keeps the pixel range below in int's range)
  if (!(film.x > -fr - 1 && film.x < W + fr + 1 && film.y > -fr - 1 && film.y < H + fr + 1)) return;
  const dvec3 to_cam = eye - x;
  const double r = glm::length(to_cam);
  const dvec3 wc = to_cam / r, wl = -ray.d;
  // the surface as the camera ray through x would build it: normals facing the camera, the
  // geometric one where the interpolated one faces away
  Hit hc = hit;
  hc.t = r;
  const Surface sc = t_.surface(Ray{eye, -wc}, hc);
  std::unique_ptr<Bsdf> b = t_.bsdf(sc);
  const dvec3 f = b->eval(wc, wl);        // f(wo = wc, wi = wl) |wl.ns|; 0 below the surface
  if (finite(f) && max3(f) <= 0) return;  // non-finite ones go on, to be counted
  const Ray shadow = Tracer::spawn(sc, wc);
  if (t_.blocked(shadow, glm::length(eye - shadow.o))) return;
  // film density: du = dw / (s^2 cos^3) and dw = dA |wc.ng| / r^2; the light path's density of
  // arrival per area carries |wl.ng|, which f's |wl.ns| replaces. With a thin lens, r and cos_c
  // are the lens point's: for a fixed lens point the film position is a function of the
  // direction to x with the same density (a shift by the lens offset over the focus distance),
  // and the uniform lens point's density 1 / area cancels the 1 / area of the lens' importance.
  const double s = camera_.pixel_pitch();
  const dvec3 c = beta * f * std::abs(glm::dot(wc, sc.ng)) /
                  (std::abs(glm::dot(wl, sc.ng)) * r * r * s * s * cos_c * cos_c * cos_c);
  // every pixel whose centre the filter's support around film reaches
  const int x0 = std::max(0, static_cast<int>(std::ceil(film.x - 0.5 - fr)));
  const int x1 = std::min(W - 1, static_cast<int>(std::floor(film.x - 0.5 + fr)));
  const int y0 = std::max(0, static_cast<int>(std::ceil(film.y - 0.5 - fr)));
  const int y1 = std::min(H - 1, static_cast<int>(std::floor(film.y - 0.5 + fr)));
  for (int py = y0; py <= y1; ++py)
    for (int px = x0; px <= x1; ++px) {
      const double w = filter_density(filter, dvec2(film.x - (px + 0.5), film.y - (py + 0.5)));
      if (w > 0) out.push_back({py * W + px, w * c});
    }
}

}  // namespace lucent::ref
