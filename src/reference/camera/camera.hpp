#pragma once
// The reference's camera (docs/rendering-model.md, "Camera and film"): pinhole or thin lens,
// film positions drawn from the pixel filter (camera/filter.cpp).
#include "reference/common.hpp"
#include "reference/sampler.hpp"

namespace lucent::ref {

/// Offset of a sample from its pixel's centre, in pixels, drawn from the film's filter.
dvec2 filter_offset(const Filter& filter, const Sampler& rng);
/// The normalized density (per pixel^2) with which filter_offset draws `offset`: what light
/// tracing weighs a film position by, for each pixel whose centre is within the filter's radius.
double filter_density(const Filter& filter, dvec2 offset);

class CameraModel {
 public:
  explicit CameraModel(const Scene& scene);
  /// The ray of one camera sample of pixel (x, y), (0, 0) the top-left one.
  Ray ray(int x, int y, const Sampler& rng) const;

  /// Light tracing: the film position (fx, fy), in pixels, of the pinhole ray through world
  /// point x, and cos_c = forward . (x - position) / |x - position|; false when x is not in
  /// front of the camera (cos_c <= 0).
  bool project(const dvec3& x, dvec2& film, double& cos_c) const;
  /// Light tracing with a thin lens: the lens point `origin` drawn from (u1, u2) as ray() draws
  /// it (the position for a pinhole), the film position of the camera rays from it that reach
  /// x (they cross the focal plane where the line from origin through x does), and cos_c =
  /// forward . (x - origin) / |x - origin|; false when x is not in front of origin.
  bool project_lens(const dvec3& x, double u1, double u2, dvec2& film, double& cos_c,
                    dvec3& origin) const;
  /// s = 2 tan(fov / 2) / H: the side of a pixel on the plane at distance 1.
  double pixel_pitch() const { return 2 * tan_half_ / height_; }
  const Filter& filter() const { return filter_; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  Filter filter_;
  dvec3 pos_, right_, up_, fwd_;
  double tan_half_ = 0, aspect_ = 1, lens_ = 0, focus_ = 0;
  dvec3 lens_point(double u1, double u2) const;  ///< polar map of the aperture disk
  int width_ = 1, height_ = 1;
};

}  // namespace lucent::ref
