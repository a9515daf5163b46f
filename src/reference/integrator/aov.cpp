// The AOVs (first-hit outputs), one function per entry of LC_AOV_TYPES; radiance() traces the
// camera ray and returns 0 on a miss.
#include "reference/integrator/integrator.hpp"

namespace lucent::ref {

/// albedo: diffuse, plastic: albedo; mirror, conductor: specular; dielectrics: tint (Bsdf::albedo).
dvec3 aov_albedo(const Tracer& t, const Ray&, const Hit&, const Surface& s, const Sampler&) {
  return t.bsdf(s)->albedo();
}

/// normal: the shading normal, facing the camera.
dvec3 aov_normal(const Tracer&, const Ray&, const Hit&, const Surface& s, const Sampler&) {
  return s.ns;
}

/// depth: the distance along the camera ray.
dvec3 aov_depth(const Tracer&, const Ray&, const Hit& hit, const Surface&, const Sampler&) {
  return dvec3(hit.t);
}

/// ao: 1 when a cosine-distributed direction about the shading normal reaches no surface within
/// ao_distance (0: unbounded), else 0.
dvec3 aov_ao(const Tracer& t, const Ray&, const Hit&, const Surface& s, const Sampler& rng) {
  dvec3 wi =
      cosine_direction(s.ns, rng.bounce(0, LC_DIM_BSDF_UV), rng.bounce(0, LC_DIM_BSDF_UV + 1));
  if (glm::dot(wi, s.ng) <= 0) return dvec3(0.0);  // into the surface itself
  double dist = t.scene.integrator.ao_distance > 0 ? t.scene.integrator.ao_distance : kInf;
  return t.blocked(Tracer::spawn(s, wi), dist) ? dvec3(0.0) : dvec3(1.0);
}

/// primitive: 1 + the primitive's index in scene order (the spheres, then the triangles).
dvec3 aov_primitive(const Tracer& t, const Ray&, const Hit& hit, const Surface&, const Sampler&) {
  return dvec3(double(t.world.scene_index(hit.prim) + 1));
}

}  // namespace lucent::ref
