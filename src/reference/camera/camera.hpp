#pragma once
// The reference's camera (docs/rendering-model.md, "Camera and film"): pinhole or thin lens,
// film positions drawn from the pixel filter (camera/filter.cpp).
#include "reference/common.hpp"
#include "reference/sampler.hpp"

namespace lucent::ref {

/// Offset of a sample from its pixel's centre, in pixels, drawn from the film's filter.
dvec2 filter_offset(const Filter& filter, const Sampler& rng);

class CameraModel {
 public:
  explicit CameraModel(const Scene& scene);
  /// The ray of one camera sample of pixel (x, y), (0, 0) the top-left one.
  Ray ray(int x, int y, const Sampler& rng) const;

 private:
  Filter filter_;
  dvec3 pos_, right_, up_, fwd_;
  double tan_half_ = 0, aspect_ = 1, lens_ = 0, focus_ = 0;
  int width_ = 1, height_ = 1;
};

}  // namespace lucent::ref
