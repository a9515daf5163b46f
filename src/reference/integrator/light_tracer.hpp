#pragma once
// Caustics by light tracing (integrator.caustics, docs/rendering-model.md, "Caustics by light
// tracing"): one light path per camera sample, traced from a light through a delta scattering
// (mirror, smooth glass), then any scatterings, and connected to the camera (its pinhole or a
// point of its thin lens) at every non-delta vertex after the first (the paths E N (N|S)* S L). The
// path integrator leaves out the same paths (path.cpp), so that the two estimators split path space
// and their sum estimates the path integrator's image, plus point lights' caustics.
#include <vector>

#include "reference/camera/camera.hpp"
#include "reference/integrator/integrator.hpp"

namespace lucent::ref {

/// A light path's contribution c_p to pixel p (index y * W + x).
struct Splat {
  int pixel;
  dvec3 c;
};

class LightTracer {
 public:
  LightTracer(const Tracer& tracer, const CameraModel& camera);

  /// The light path of one camera sample (rng: its pixel, sample index and seed; the path draws
  /// from LC_DIM_LIGHT_PATH on): appends its contributions to `out`, one per connection and
  /// pixel (a path may connect at several vertices, and two of them may reach one pixel).
  /// Contributions are not divided by the number of light paths N; non-finite ones are appended
  /// as they are.
  void trace(const Sampler& rng, std::vector<Splat>& out) const;

 private:
  const Tracer& t_;
  const CameraModel& camera_;

  /// Connects vertex `hit` of light ray `ray` (throughput beta arriving there) to the camera:
  /// to its pinhole, or to the point (lens_u, lens_v) of its thin lens (CameraModel::project_lens).
  void connect(const Ray& ray, const Hit& hit, const dvec3& beta, double lens_u, double lens_v,
               std::vector<Splat>& out) const;
};

}  // namespace lucent::ref
