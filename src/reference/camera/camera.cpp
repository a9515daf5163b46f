// The reference's camera: basis from position, look_at, up and roll; pinhole rays through the
// film position; thin lens by a polar point of the aperture disk (the kernel uses another
// mapping of the disk: the same distribution, different numbers).
#include "reference/camera/camera.hpp"

namespace lucent::ref {

CameraModel::CameraModel(const Scene& scene) : filter_(scene.film.filter) {
  const Camera& c = scene.camera;
  pos_ = c.position;
  fwd_ = unit(c.look_at - c.position);  // unit(): tiny vectors (1e-170) are directions too
  dvec3 right = unit(glm::cross(fwd_, unit(c.up)));
  dvec3 up = glm::cross(right, fwd_);
  // roll: right and up turn counter-clockwise as seen looking along forward, i.e. right moves
  // towards up
  double r = c.roll_degrees * kPi / 180;
  right_ = std::cos(r) * right + std::sin(r) * up;
  up_ = -std::sin(r) * right + std::cos(r) * up;
  width_ = scene.film.width;
  height_ = scene.film.height;
  tan_half_ = std::tan(c.fov_degrees * kPi / 360);
  aspect_ = double(width_) / height_;
  lens_ = c.aperture;
  focus_ = c.focus_distance > 0 ? c.focus_distance : glm::length(c.look_at - c.position);
}

Ray CameraModel::ray(int x, int y, const Sampler& rng) const {
  dvec2 off = filter_offset(filter_, rng);
  double fx = x + 0.5 + off.x, fy = y + 0.5 + off.y;
  double ndc_x = (2 * fx / width_ - 1) * tan_half_ * aspect_;
  double ndc_y = (1 - 2 * fy / height_) * tan_half_;
  Ray ray{pos_, glm::normalize(fwd_ + ndc_x * right_ + ndc_y * up_)};
  if (lens_ > 0) {
    dvec3 focus = pos_ + (focus_ / glm::dot(ray.d, fwd_)) * ray.d;
    ray.o = lens_point(rng.get(LC_DIM_LENS), rng.get(LC_DIM_LENS + 1));
    ray.d = glm::normalize(focus - ray.o);
  }
  return ray;
}

dvec3 CameraModel::lens_point(double u1, double u2) const {
  double lr = lens_ * std::sqrt(u1), phi = 2 * kPi * u2;
  return pos_ + lr * std::cos(phi) * right_ + lr * std::sin(phi) * up_;
}

bool CameraModel::project_lens(const dvec3& x, double u1, double u2, dvec2& film, double& cos_c,
                               dvec3& origin) const {
  if (lens_ <= 0) {
    origin = pos_;
    return project(x, film, cos_c);
  }
  origin = lens_point(u1, u2);
  dvec3 v = x - origin;
  double len = glm::length(v), depth = glm::dot(v, fwd_);
  if (!(len > 0) || !(depth > 0)) return false;
  cos_c = depth / len;
  // ray() aims every lens point of film position u at the focal plane's point that the pinhole
  // ray of u crosses: the film position is the pinhole's of that point
  double unused;
  return project(origin + (focus_ / depth) * v, film, unused);
}

bool CameraModel::project(const dvec3& x, dvec2& film, double& cos_c) const {
  dvec3 v = x - pos_;
  double len = glm::length(v);
  if (!(len > 0)) return false;
  cos_c = glm::dot(v, fwd_) / len;
  if (!(cos_c > 0)) return false;
  // the pinhole direction is normalize(fwd + ndc_x right + ndc_y up): scale v to fwd . v = 1
  double ndc_x = glm::dot(v, right_) / glm::dot(v, fwd_);
  double ndc_y = glm::dot(v, up_) / glm::dot(v, fwd_);
  film.x = (ndc_x / (tan_half_ * aspect_) + 1) * width_ / 2;
  film.y = (1 - ndc_y / tan_half_) * height_ / 2;
  return true;
}

}  // namespace lucent::ref
