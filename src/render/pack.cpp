#include "render/pack.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <map>

#include "lucent/error.hpp"
#include "lucent/limits.hpp"
#include "lucent/types.hpp"
#include "scene/loaders.hpp"
#include "scene/material_type.hpp"
#include "scene/validate.hpp"

namespace lucent::render_detail {

namespace {

using scene_detail::put3;

/// Whether material `m` can scatter by a delta lobe (MaterialTypeDef::delta: a mirror, smooth
/// glass, a rough dielectric of ior 1): a surface a caustic path needs.
bool scatters_by_delta(const Material& m) {
  const auto is_delta = scene_detail::material_type_def(m.type).delta;
  return is_delta && is_delta(m);
}

bool finite3(const glm::dvec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

/// The primitives a BVH is built from are the same: triangle vertices, sphere centres and radii.
bool same_geometry(const PackedScene& a, const PackedScene& b) {
  if (a.triangles.size() != b.triangles.size() || a.spheres.size() != b.spheres.size())
    return false;
  for (size_t i = 0; i < a.triangles.size(); ++i) {
    const lc_triangle &s = a.triangles[i], &t = b.triangles[i];
    if (!std::equal(s.v0, s.v0 + 3, t.v0) || !std::equal(s.v1, s.v1 + 3, t.v1) ||
        !std::equal(s.v2, s.v2 + 3, t.v2))
      return false;
  }
  for (size_t i = 0; i < a.spheres.size(); ++i) {
    const lc_sphere &s = a.spheres[i], &t = b.spheres[i];
    if (!std::equal(s.center, s.center + 3, t.center) || s.radius != t.radius) return false;
  }
  return true;
}

/// Stores the unit normal n in t's fourth lanes, rounded to float; a component below the smallest
/// normal float becomes 0, so that the kernel's aligned vertex loads never carry a subnormal
/// (types.h, lc_triangle).
void put_normal(lc_triangle& t, const glm::dvec3& n) {
  auto f = [](double c) {
    const float r = static_cast<float>(c);
    return std::fabs(r) < std::numeric_limits<float>::min() ? 0.0f : r;
  };
  t.ng_x = f(n.x);
  t.ng_y = f(n.y);
  t.ng_z = f(n.z);
}

static_assert(static_cast<lc_uint>(TextureWrap::Repeat) == LC_WRAP_REPEAT &&
                  static_cast<lc_uint>(TextureWrap::Clamp) == LC_WRAP_CLAMP &&
                  static_cast<lc_uint>(TextureWrap::Mirror) == LC_WRAP_MIRROR,
              "lucent::TextureWrap's values are the kernel's LC_WRAP_*");

/// The period of a wrap mode in texture space (repeat 1, mirror 2; clamp has none: 0).
double wrap_period(TextureWrap w) {
  return w == TextureWrap::Repeat ? 1 : w == TextureWrap::Mirror ? 2 : 0;
}

/// The texture header of texture `t` (its texels from `offset`) mapped as `m` says (a
/// device_texture_mapping: its offsets reduced, so that a large one keeps its fraction in float).
lc_texture texture_header(const Texture& t, lc_uint offset, const Material& m) {
  lc_texture d{};
  d.offset = offset;
  d.width = static_cast<lc_uint>(t.width);
  d.height = static_cast<lc_uint>(t.height);
  d.wrap = static_cast<lc_uint>(m.albedo_wrap_u) |
           (static_cast<lc_uint>(m.albedo_wrap_v) << LC_WRAP_V_SHIFT);
  for (int k = 0; k < 2; ++k) {
    d.uv_scale[k] = static_cast<float>(m.albedo_uv_scale[k]);
    d.uv_offset[k] = static_cast<float>(m.albedo_uv_offset[k]);
  }
  return d;
}

}  // namespace

Material device_texture_mapping(const Material& m, std::size_t texture_count) {
  Material d;
  if (m.albedo_texture < 0 || static_cast<std::size_t>(m.albedo_texture) >= texture_count) return d;
  d.albedo_wrap_u = m.albedo_wrap_u;
  d.albedo_wrap_v = m.albedo_wrap_v;
  d.albedo_uv_scale = m.albedo_uv_scale;
  const TextureWrap wrap[2] = {m.albedo_wrap_u, m.albedo_wrap_v};
  for (int k = 0; k < 2; ++k) {
    const double period = wrap_period(wrap[k]), o = m.albedo_uv_offset[k];
    double r = o;
    if (period > 0 && std::isfinite(o)) {
      r = o - period * std::floor(o / period);
      if (r >= period) r -= period;  // (o a tiny negative number: the sum rounds up to period)
      if (r == 0) r = 0;             // not -0
    }
    d.albedo_uv_offset[k] = r;
  }
  return d;
}

bool needs_mapping_code(const Material& m, std::size_t texture_count, bool on_spheres) {
  const Material d = device_texture_mapping(m, texture_count);
  if (d.albedo_wrap_u != TextureWrap::Repeat || d.albedo_wrap_v != TextureWrap::Repeat) return true;
  return on_spheres && !d.default_albedo_mapping();
}

bool set_triangle_normal(lc_triangle& t) {
  glm::dvec3 v0(t.v0[0], t.v0[1], t.v0[2]), v1(t.v1[0], t.v1[1], t.v1[2]);
  glm::dvec3 v2(t.v2[0], t.v2[1], t.v2[2]);
  glm::dvec3 n = glm::cross(v1 - v0, v2 - v0);
  double len = glm::length(n);
  if (!(len > 0) || !std::isfinite(len)) return false;
  put_normal(t, n / len);
  return true;
}

lc_camera pack_camera(const Camera& c, int width, int height) {
  lc_camera cam{};
  // unit(): a tiny up or look_at - position (1e-170) is a direction like any other
  glm::dvec3 fwd = scene_detail::unit(c.look_at - c.position);
  glm::dvec3 right = scene_detail::unit(glm::cross(fwd, scene_detail::unit(c.up)));
  glm::dvec3 up = glm::cross(right, fwd);
  if (c.roll_degrees != 0) {
    // counter-clockwise as seen looking along forward: right turns towards up
    double a = glm::radians(c.roll_degrees);
    glm::dvec3 r2 = std::cos(a) * right + std::sin(a) * up;
    up = -std::sin(a) * right + std::cos(a) * up;
    right = r2;
  }
  put3(cam.position, c.position);
  put3(cam.right, right);
  put3(cam.up, up);
  put3(cam.forward, fwd);
  cam.tan_half_fov = static_cast<float>(std::tan(glm::radians(c.fov_degrees) * 0.5));
  cam.aspect = static_cast<float>(width) / static_cast<float>(height);
  cam.lens_radius = static_cast<float>(c.aperture);
  // 0: the distance to look_at, resolved here so that it follows a camera moved after loading.
  // That distance may exceed a float where look_at's coordinates do not (a pinhole aimed at
  // [-3e38, -1e38, -3e38]): the largest float then, a focal plane as far as infinity.
  cam.focus_distance = static_cast<float>(
      c.focus_distance > 0 ? c.focus_distance
                           : std::min(glm::length(c.look_at - c.position), double(FLT_MAX)));
  return cam;
}

// The camera and the geometry are stored in float with either --precision: a pixel whose
// footprint at the look-at distance spans a few float steps of the coordinates there (a fov of
// 1e-4 degrees, a camera 1e8 from the origin looking at something 10 away) renders their
// rounding, staircase edges and a shift of up to a pixel, without a word (the reference, in
// double, does not). Said when a pixel spans fewer than 4 steps. The distance is the look-at's,
// or the scene's bounds' when they are farther (a look-at 1 ahead of a camera 5000 from what it
// sees warned).
/// Whether a stored surface (a triangle's plane within its bounds, a sphere) lies within `reach`
/// of point `o`.
static bool surface_within(const PackedScene& p, const glm::dvec3& o, double reach) {
  for (const lc_triangle& t : p.triangles) {
    bool inside = true;
    for (int a = 0; a < 3 && inside; ++a) {
      const double lo = std::min({t.v0[a], t.v1[a], t.v2[a]}),
                   hi = std::max({t.v0[a], t.v1[a], t.v2[a]});
      inside = o[a] >= lo - reach && o[a] <= hi + reach;
    }
    if (inside && std::abs(t.ng_x * (o.x - t.v0[0]) + t.ng_y * (o.y - t.v0[1]) +
                           t.ng_z * (o.z - t.v0[2])) <= reach)
      return true;
  }
  for (const lc_sphere& s : p.spheres)
    if (std::abs(glm::length(o - glm::dvec3(s.center[0], s.center[1], s.center[2])) - s.radius) <=
        reach)
      return true;
  return false;
}

static void warn_camera_precision(const Scene& scene, const Camera& c, const PackedScene& p) {
  // a surface within a few float steps of the camera: the camera's rounding can put it on the
  // surface or past it, with either precision (a wall 0.0002 in front of a camera at 1e4, where
  // floats are 0.001 apart, was not seen: the camera rounded onto its plane). Checked only when
  // the camera is that near the scene's bounds.
  double at = 0, outside = 0;
  for (int i = 0; i < 3; ++i) {
    at = std::max(at, std::abs(c.position[i]));
    outside = std::max({outside, p.bounds_min[i] - c.position[i], c.position[i] - p.bounds_max[i]});
  }
  const double apart = at * std::ldexp(1.0, -23), reach = 4 * apart;
  if (reach > 0 && outside <= reach && surface_within(p, c.position, reach)) {
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "camera: a surface lies within %.3g of the camera, at coordinates up to %.3g "
                  "where floats are up to %.3g apart: with either precision the camera's stored "
                  "position may fall on the surface or past it, which is then not seen; move the "
                  "camera away from it or the scene nearer the origin",
                  reach, at, apart);
    scene_detail::warn(scene_detail::in_file(scene.path, buf));
  }
  double to_bounds = 0;  // from the camera to the nearest point of the scene's bounds
  for (int i = 0; i < 3; ++i) {
    const double out =
        std::max({0.0, p.bounds_min[i] - c.position[i], c.position[i] - p.bounds_max[i]});
    to_bounds += out * out;
  }
  const double distance = std::max(glm::length(c.look_at - c.position), std::sqrt(to_bounds));
  const double pitch = 2.0 * std::tan(glm::radians(c.fov_degrees) * 0.5) / scene.film.height;
  double coordinate = distance;
  for (int i = 0; i < 3; ++i)
    coordinate = std::max({coordinate, std::abs(c.position[i]), std::abs(c.look_at[i])});
  const double step = coordinate * std::ldexp(1.0, -23);  // float's spacing there, at most
  const double steps = distance * pitch / step;
  if (!(steps < 4)) return;
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "camera: a pixel spans %.2g float steps of the coordinates at the look-at "
                "distance (fov %.3g degrees on %d rows, look-at %.3g away, coordinates up to "
                "%.3g), fewer than 4: the image shows the float rounding of the camera and the "
                "scene (staircase edges, a shift of up to a pixel) with either precision; widen "
                "the fov, lower the film's height or move the scene nearer the origin",
                steps, c.fov_degrees, scene.film.height, distance, coordinate);
  scene_detail::warn(scene_detail::in_file(scene.path, buf));
}

namespace {

/// The largest magnitude of a stored point's coordinates.
double max_abs3(const float* v) {
  return std::max({std::abs(double(v[0])), std::abs(double(v[1])), std::abs(double(v[2]))});
}

/// A sphere that rays can hit: a finite centre and a positive finite radius (pack_scene keeps
/// the others, never hit).
bool hittable(const lc_sphere& sp) {
  return sp.radius > 0 && std::isfinite(sp.radius) && std::isfinite(sp.center[0]) &&
         std::isfinite(sp.center[1]) && std::isfinite(sp.center[2]);
}

/// Whether the bounds of the triangle (a, b, c) lie farther than r from the point p on an axis.
bool bounds_apart(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c,
                  const glm::dvec3& p, double r) {
  for (int k = 0; k < 3; ++k)
    if (std::min({a[k], b[k], c[k]}) > p[k] + r || std::max({a[k], b[k], c[k]}) < p[k] - r)
      return true;
  return false;
}

/// How many lights the checks below compare with every primitive: at most ~2e7 tests, so the
/// first lights only in a scene of very many (at least one).
size_t most_against_every_primitive(const PackedScene& packed) {
  const size_t prims = packed.triangles.size() + packed.spheres.size();
  return std::max<size_t>(1, size_t(20000000) / std::max<size_t>(1, prims));
}

/// The distance from the point c to the triangle (a, b, d), in double.
double point_triangle_distance(const glm::dvec3& c, const glm::dvec3& a, const glm::dvec3& b,
                               const glm::dvec3& d) {
  const glm::dvec3 n = glm::cross(b - a, d - a);
  const double len = glm::length(n);
  auto segment = [&](const glm::dvec3& p, const glm::dvec3& q) {
    const glm::dvec3 e = q - p;
    const double ee = glm::dot(e, e);
    const double t = ee > 0 ? std::clamp(glm::dot(c - p, e) / ee, 0.0, 1.0) : 0.0;
    return glm::length(c - (p + t * e));
  };
  const double edges = std::min({segment(a, b), segment(b, d), segment(d, a)});
  if (!(len > 0)) return edges;
  const glm::dvec3 u = n / len;
  const double s = glm::dot(c - a, u);
  const glm::dvec3 f =
      c - s * u;  // c's foot on the plane: inside when on the inner side of all edges
  if (glm::dot(glm::cross(b - a, f - a), u) >= 0 && glm::dot(glm::cross(d - b, f - b), u) >= 0 &&
      glm::dot(glm::cross(a - d, f - d), u) >= 0)
    return std::abs(s);
  return edges;
}

}  // namespace

std::string float_rounding_note(const PackedScene& packed) {
  constexpr double kTinySceneSize = 1e-10;  // the diagonal of the scene's bounds, below which
                                            // float's products underflow (see below)
  double largest = 0;                       // the largest coordinate magnitude of a primitive
  std::vector<double> sizes;
  const size_t n = packed.triangles.size() + packed.spheres.size();
  const size_t stride = std::max<size_t>(1, n / 100000);  // a sample of at most ~1e5 sizes
  size_t i = 0;
  for (const lc_triangle& t : packed.triangles) {
    const float* v[3] = {t.v0, t.v1, t.v2};
    lc_triangle normal = t;  // a triangle of no area in float is never hit: nothing leaves it
    if (!set_triangle_normal(normal)) continue;
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 3; ++c) largest = std::max(largest, std::abs(double(v[k][c])));
    if (i++ % stride) continue;
    double edge = 0;
    for (int k = 0; k < 3; ++k) {
      const float *a = v[k], *b = v[(k + 1) % 3];
      edge =
          std::max(edge, std::hypot(double(a[0]) - b[0], double(a[1]) - b[1], double(a[2]) - b[2]));
    }
    sizes.push_back(edge);
  }
  for (const lc_sphere& sp : packed.spheres) {
    // never hit (a non-finite centre counted as an infinite coordinate: "up to inf here")
    if (!hittable(sp)) continue;
    for (int c = 0; c < 3; ++c)
      largest = std::max(largest, std::abs(double(sp.center[c])) + sp.radius);
    if (i++ % stride == 0) sizes.push_back(2.0 * sp.radius);
  }
  if (sizes.empty()) return "";
  const size_t k = (sizes.size() - 1) / 10;
  std::nth_element(sizes.begin(), sizes.begin() + k, sizes.end());
  const double feature = sizes[k];
  const double offset = largest * std::ldexp(1.0, -20);  // 2 x 7 float epsilons, about
  double diagonal = 0;                                   // of the scene's bounds
  for (int c = 0; c < 3; ++c) {
    const double e = double(packed.bounds_max[c]) - packed.bounds_min[c];
    diagonal += e * e;
  }
  diagonal = std::sqrt(diagonal);
  // the triangle test's depth is a product of three coordinate differences between the ray's
  // origin and the vertices (kernels/geom/triangle.cl: T), about size^3, which leaves float's
  // normal range (1.2e-38) below a size of 2.3e-13: a Cornell box scaled by 1e-13 in float gave
  // wrong distances, by 1e-15 half its brightness, by 1e-16 a black image; double renders them
  // right. 1e-10: a margin of 100 for rays meeting primitives at a hundredth of the scene's size.
  if (diagonal > 0 && diagonal < kTinySceneSize) {
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "in float precision, the intersection tests multiply coordinate differences "
                  "whose products fall below float's range in a scene this small (size %.3g, "
                  "below %.0e): primitives may be missed or met at wrong distances, and the "
                  "image too dark, black or too bright (a scene of size 1e-30 under a sphere "
                  "light rendered white); use --precision double or scale the scene up",
                  diagonal, kTinySceneSize);
    return buf;
  }
  // offsets beyond 1/16 of the small features (a huge ground triangle under small objects: 1/8
  // first, under which a sphere of 0.1 on a floor of +-1e4, at 1/10.5, had contact shadows 1.8
  // times too bright, image-mean z 13 against the reference; the dragon on a quad of +-100, at
  // 1/32 of its 10th-percentile edge, renders the same in both precisions), or
  // coordinates 100 times the scene's size (a scene far from the origin: its offsets and the
  // rounding of its hit points, 1e-4 of its size, let rays out of closed shells at their edges
  // and move shadow rays towards the lights; at 700 times, under the 1000 first chosen, a sphere
  // light over a plane rendered 0.8% bright, a decal 1e-4 of the scene above a floor 0.9%, a
  // thin slab's shadow 2.6%, all without a word; at 70 times they render right)
  if (!(offset > feature / 16) && !(largest > 100 * diagonal)) return "";
  char buf[640];
  std::snprintf(buf, sizeof buf,
                "in float precision, rays leave surfaces offset by their rounding, up to %.2g "
                "here (coordinates up to %.3g, a scene of size %.3g, small features of %.2g, "
                "the 10th percentile of primitive sizes): shadows and contacts of small objects "
                "may be wrong and closed shells may leak light at their edges; use --precision "
                "double, split large triangles or move the scene nearer the origin",
                offset, largest, diagonal, feature);
  return buf;
}

SceneScale scene_scale(const Scene& scene) {
  SceneScale out;
  std::vector<double> sizes;
  const size_t n = scene.triangles.size() + scene.spheres.size();
  const size_t stride = std::max<size_t>(1, n / 100000);  // a sample of at most ~1e5 sizes
  size_t i = 0;
  auto moved = [](const glm::dvec3& p) { return glm::length(p - glm::dvec3(glm::vec3(p))); };
  for (const Triangle& t : scene.triangles) {
    glm::dvec3 v[3];
    bool valid = true;
    for (int k = 0; k < 3; ++k) {
      valid = valid && t.v[k] >= 0 && static_cast<size_t>(t.v[k]) < scene.positions.size();
      if (valid) v[k] = scene.positions[static_cast<size_t>(t.v[k])];
    }
    if (!valid) continue;
    const double edge =
        std::max({glm::length(v[1] - v[0]), glm::length(v[2] - v[1]), glm::length(v[0] - v[2])});
    if (!(edge > 0) || !std::isfinite(edge)) continue;  // dropped by pack_scene
    out.rounding = std::max({out.rounding, moved(v[0]), moved(v[1]), moved(v[2])});
    out.largest = std::max({out.largest, scene_detail::max_abs(v[0]), scene_detail::max_abs(v[1]),
                            scene_detail::max_abs(v[2])});
    if (i++ % stride == 0) sizes.push_back(edge);
  }
  for (const Sphere& sp : scene.spheres) {
    if (!(sp.radius > 0) || !std::isfinite(sp.radius) || !std::isfinite(moved(sp.center))) continue;
    out.rounding =
        std::max(out.rounding, moved(sp.center) + std::abs(double(float(sp.radius)) - sp.radius));
    out.largest = std::max(out.largest, scene_detail::max_abs(sp.center) + sp.radius);
    if (i++ % stride == 0) sizes.push_back(2.0 * sp.radius);
  }
  if (sizes.empty()) return out;
  const size_t k = (sizes.size() - 1) / 10;
  std::nth_element(sizes.begin(), sizes.begin() + k, sizes.end());
  out.feature = sizes[k];
  return out;
}

std::string stored_rounding_note(const Scene& scene) {
  const SceneScale scale = scene_scale(scene);
  if (!(scale.rounding > scale.feature / 16)) return "";
  char buf[720];
  std::snprintf(buf, sizeof buf,
                "the scene's coordinates are stored in float in either precision, which moves a "
                "surface by up to %.2g here, more than 1/16 of its small features (%.2g, the "
                "10th percentile of primitive sizes): small objects' contacts and shadows are "
                "those of the moved surface, with --precision double too (a ground sphere of "
                "radius 1e7 whose centre rounded by 0.3 left a sphere of 0.5 floating); give "
                "coordinates that floats hold near the small objects, use triangles instead of a "
                "huge sphere, or move the scene nearer the origin",
                scale.rounding, scale.feature);
  return buf;
}

std::string tiny_emitter_note(const PackedScene& packed) {
  double diagonal = 0;  // of the scene's bounds
  for (int c = 0; c < 3; ++c) {
    const double e = double(packed.bounds_max[c]) - packed.bounds_min[c];
    diagonal += e * e;
  }
  diagonal = std::sqrt(diagonal);
  double smallest = INFINITY;  // an emitter's size: a sphere's radius, a triangle's sqrt(area)
  for (const lc_light& l : packed.lights) {
    if (l.type == LC_LIGHT_SPHERE && l.p.sphere.sphere < packed.spheres.size())
      smallest = std::min(smallest, double(packed.spheres[l.p.sphere.sphere].radius));
    if (l.type == LC_LIGHT_TRIANGLE)
      smallest = std::min(smallest, std::sqrt(double(l.p.triangle.area)));
  }
  // light sampling's density, 1 / the emitter's solid angle, is a float: past 3.4e38 (an emitter
  // below about 1e-19 of its distance) it is infinite and the sample gives nothing (a sphere light
  // of radius 1e-20 with emission 1e38 rendered black, the reference 5e-4; at 1e-19 2.7% dark)
  if (!(diagonal > 0) || !(smallest < 1e-18 * diagonal)) return "";
  char buf[600];
  std::snprintf(buf, sizeof buf,
                "an emitter of size %.2g in a scene of size %.3g subtends less than light "
                "sampling's float density can hold: its light may be lost in either precision (a "
                "sphere light of radius 1e-20 rendered black); make it larger and dimmer, or use a "
                "point light",
                smallest, diagonal);
  return buf;
}

std::vector<std::string> packing_notes(const Scene& scene, const PackedScene& packed,
                                       bool float_arithmetic) {
  std::vector<std::string> notes;
  for (std::string note :
       {float_arithmetic ? float_rounding_note(packed) : std::string(), stored_rounding_note(scene),
        emitter_cut_note(packed, float_arithmetic), point_light_note(packed, float_arithmetic),
        area_light_note(packed, float_arithmetic), tiny_emitter_note(packed)})
    if (!note.empty()) notes.push_back(scene_detail::in_file(scene.path, note));
  return notes;
}

std::string emitter_cut_note(const PackedScene& packed, bool float_arithmetic) {
  const size_t most_emitters = most_against_every_primitive(packed);
  size_t emitters = 0;
  double worst = 0, worst_h = 0, worst_m = 0, worst_r = 0;
  for (size_t e = 0; e < packed.spheres.size() && emitters < most_emitters; ++e) {
    const lc_sphere& E = packed.spheres[e];
    if (E.light == LC_INVALID || !hittable(E)) continue;
    ++emitters;
    const glm::dvec3 ce(E.center[0], E.center[1], E.center[2]);
    const double re = E.radius;
    // the shadow rays' margin short of the emitter, 4 of its point error bounds (light/sphere.cl)
    // (in double: the rounding of the stored coordinates, float in both precisions, which moved
    // the ceiling of the room below with walls of radius 1e6 by 0.025, 9.5% bright in double)
    const int own_exp = float_arithmetic ? -19 : -24, cutter_exp = float_arithmetic ? -20 : -24;
    const double own = (max_abs3(E.center) + re) * std::ldexp(1.0, own_exp);
    auto consider = [&](double h, double cutter) {  // h: the thinner part's depth
      const double m = std::max(own, cutter);
      if (h > 0 && m / h > worst) {
        worst = m / h;
        worst_h = h;
        worst_m = m;
        worst_r = re;
      }
    };
    for (size_t i = 0; i < packed.spheres.size(); ++i) {
      const lc_sphere& S = packed.spheres[i];
      if (i == e || !hittable(S)) continue;
      const glm::dvec3 cs(S.center[0], S.center[1], S.center[2]);
      const double rs = S.radius, d = glm::length(cs - ce);
      if (!(d > std::abs(re - rs)) || !(d < re + rs)) continue;  // the surfaces do not cross
      // the plane of the crossing circle, x from ce towards cs: E's parts have depths re -+ x
      const double x = ((d - rs) * (d + rs) + re * re) / (2 * d);
      consider(re - std::abs(x), (max_abs3(S.center) + rs) * std::ldexp(1.0, cutter_exp));
    }
    for (const lc_triangle& t : packed.triangles) {
      const glm::dvec3 a(t.v0[0], t.v0[1], t.v0[2]), b(t.v1[0], t.v1[1], t.v1[2]),
          c(t.v2[0], t.v2[1], t.v2[2]);
      if (bounds_apart(a, b, c, ce, re)) continue;  // the triangle's bounds miss the sphere's
      // inside the sphere entirely: it cuts no part of its surface
      if (glm::length(a - ce) < re && glm::length(b - ce) < re && glm::length(c - ce) < re)
        continue;
      if (!(point_triangle_distance(ce, a, b, c) < re)) continue;
      const glm::dvec3 n = glm::cross(b - a, c - a);
      const double len = glm::length(n);
      if (!(len > 0)) continue;
      const double s = std::abs(glm::dot(ce - a, n / len));  // the plane cuts a cap of re - s
      consider(re - s, std::max({max_abs3(t.v0), max_abs3(t.v1), max_abs3(t.v2)}) *
                           std::ldexp(1.0, cutter_exp));
    }
  }
  // the part's error is about 3% of m / h in the image (a lamp of radius 600 poking 0.27 through
  // a smallpt ceiling sphere of 1e5: m / h 0.7, 1.2% bright; poking 2: 0.1, 0.3%)
  if (!(worst > 1.0 / 16)) return "";
  char buf[720];
  if (float_arithmetic)
    std::snprintf(buf, sizeof buf,
                  "in float precision, a sphere light (radius %.3g) is cut by another surface into "
                  "a part only %.2g thick, and rays near it are offset by their rounding, up to "
                  "%.2g here: how much of the light shows may be wrong (a smallpt-style lamp "
                  "poking 0.27 into a wall of radius 1e5 rendered 1.2%% bright); use --precision "
                  "double, walls of triangles instead of huge spheres, or a light farther from "
                  "the cut",
                  worst_r, worst_h, worst_m);
  else
    std::snprintf(buf, sizeof buf,
                  "a sphere light (radius %.3g) is cut by another surface into a part only %.2g "
                  "thick, and the scene's coordinates, stored in float in either precision, are "
                  "rounded by up to %.2g there: how much of the light shows may be wrong (a "
                  "smallpt-style lamp poking 0.27 into a wall of radius 1e6 rendered 9.5%% "
                  "bright); use walls of triangles instead of huge spheres or move the cut nearer "
                  "the origin",
                  worst_r, worst_h, worst_m);
  return buf;
}

std::string point_light_note(const PackedScene& packed, bool float_arithmetic) {
  const size_t most_lights = most_against_every_primitive(packed);
  const int surface_exp = float_arithmetic ? -20 : -24;  // spawn offsets, or storage alone
  size_t lights = 0;
  double worst = 0, worst_h = 0, worst_m = 0;
  for (const lc_light& l : packed.lights) {
    if (l.type != LC_LIGHT_POINT || lights++ >= most_lights) continue;
    const float* pos = l.p.point.position;
    const glm::dvec3 p(pos[0], pos[1], pos[2]);
    double h = INFINITY, cutter = 0;  // the nearest surface's distance and coordinates there
    for (const lc_sphere& sp : packed.spheres) {
      if (!hittable(sp)) continue;
      const double d = std::abs(
          glm::length(glm::dvec3(sp.center[0], sp.center[1], sp.center[2]) - p) - sp.radius);
      if (d < h) h = d, cutter = max_abs3(sp.center) + sp.radius;
    }
    for (const lc_triangle& t : packed.triangles) {
      const glm::dvec3 a(t.v0[0], t.v0[1], t.v0[2]), b(t.v1[0], t.v1[1], t.v1[2]),
          c(t.v2[0], t.v2[1], t.v2[2]);
      if (bounds_apart(a, b, c, p, h)) continue;  // farther than the nearest surface so far
      const double d = point_triangle_distance(p, a, b, c);
      if (d < h) h = d, cutter = std::max({max_abs3(t.v0), max_abs3(t.v1), max_abs3(t.v2)});
    }
    // the light's position, stored in float, and the surface's rounding there
    const double m =
        std::max(max_abs3(pos) * std::ldexp(1.0, -24), cutter * std::ldexp(1.0, surface_exp));
    if (h > 0 && std::isfinite(h) && m / h > worst) worst = m / h, worst_h = h, worst_m = m;
  }
  if (!(worst > 1.0 / 256)) return "";
  char buf[600];
  std::snprintf(buf, sizeof buf,
                "a point light lies %.2g from a surface, and the coordinates there are rounded by "
                "up to %.2g (%s), %.2g of that distance: the light it casts near it may be wrong "
                "(a light 0.01 above a floor at 1e4 from the origin was, pixel by pixel); move "
                "the light farther from the surface or the scene nearer the origin",
                worst_h, worst_m,
                float_arithmetic ? "float precision's offsets and the stored floats"
                                 : "the coordinates are stored in float in either precision",
                worst);
  return buf;
}

std::string area_light_note(const PackedScene& packed, bool float_arithmetic) {
  if (!float_arithmetic) return "";  // double's offsets are 2^-29 of float's: none measured
  // each emitter costs a test per point and primitive: 1 point for a sphere, 7 for a triangle
  const size_t budget = most_against_every_primitive(packed);
  size_t spent = 0;
  double worst = 0, worst_s = 0, worst_h = 0, worst_m = 0;
  glm::dvec3 worst_at(0.0);
  bool worst_sphere = false;
  // An emitter's points (a sphere's centre, whose distances then lose its radius; a triangle's
  // vertices, edge midpoints and centroid, so that a sliver crossing a surface is seen), its
  // size, and the side it lights: a triangle's front (its plane through `a` with normal `n`), a
  // sphere's outside. Every lit non-emitting surface within `size` counts, the coarsest one
  // deciding (a small object beside the lamp hid the floor under it when only the nearest did).
  auto consider = [&](const std::vector<glm::dvec3>& points, double radius, double size,
                      const glm::dvec3& a, const glm::dvec3& n, size_t self_sphere,
                      size_t self_triangle, const glm::dvec3& at, bool sphere) {
    double h = INFINITY, m = 0;
    auto take = [&](double d, double coords) {
      if (!(d < size)) return;
      const double offset = coords * std::ldexp(1.0, -20);  // that surface's spawn offsets
      if (offset > m) m = offset, h = d;
    };
    auto in_front = [&](const glm::dvec3& q) { return sphere || glm::dot(q - a, n) > 0; };
    for (size_t i = 0; i < packed.spheres.size(); ++i) {
      const lc_sphere& sp = packed.spheres[i];
      if (i == self_sphere || sp.light != LC_INVALID || !hittable(sp)) continue;
      const glm::dvec3 c(sp.center[0], sp.center[1], sp.center[2]);
      const double r = sp.radius;
      // wholly behind the lamp's plane (n is not unit: r is scaled by its length)
      if (!sphere && glm::dot(c - a, n) + r * glm::length(n) <= 0) continue;
      double d = INFINITY;
      for (const glm::dvec3& q : points) {
        const double e = glm::length(c - q);
        if (sphere && e + r <= radius) continue;  // inside the lamp: sees its dark inside
        d = std::min(d, std::max(0.0, std::abs(e - r) - radius));
      }
      take(d, max_abs3(sp.center) + r);
    }
    for (size_t i = 0; i < packed.triangles.size(); ++i) {
      const lc_triangle& t = packed.triangles[i];
      if (i == self_triangle || t.light != LC_INVALID) continue;
      const glm::dvec3 b0(t.v0[0], t.v0[1], t.v0[2]), b1(t.v1[0], t.v1[1], t.v1[2]),
          b2(t.v2[0], t.v2[1], t.v2[2]);
      if (!in_front(b0) && !in_front(b1) && !in_front(b2)) continue;
      if (sphere && glm::length(b0 - points[0]) < radius && glm::length(b1 - points[0]) < radius &&
          glm::length(b2 - points[0]) < radius)
        continue;  // inside the lamp
      double d = INFINITY;
      for (const glm::dvec3& q : points)
        if (!bounds_apart(b0, b1, b2, q, size + radius))
          d = std::min(d, std::max(0.0, point_triangle_distance(q, b0, b1, b2) - radius));
      take(d, std::max({max_abs3(t.v0), max_abs3(t.v1), max_abs3(t.v2)}));
    }
    if (size > 0 && m / size > worst)
      worst = m / size, worst_s = size, worst_h = h, worst_m = m, worst_at = at,
      worst_sphere = sphere;
  };
  for (size_t i = 0; i < packed.spheres.size() && spent < budget; ++i) {
    const lc_sphere& sp = packed.spheres[i];
    if (sp.light == LC_INVALID || !hittable(sp)) continue;
    spent += 1;
    const glm::dvec3 c(sp.center[0], sp.center[1], sp.center[2]);
    consider({c}, sp.radius, sp.radius, c, glm::dvec3(0.0), i, LC_INVALID, c, true);
  }
  for (size_t i = 0; i < packed.triangles.size() && spent + 7 <= std::max<size_t>(budget, 7); ++i) {
    const lc_triangle& t = packed.triangles[i];
    if (t.light == LC_INVALID) continue;
    spent += 7;
    const glm::dvec3 a(t.v0[0], t.v0[1], t.v0[2]), b(t.v1[0], t.v1[1], t.v1[2]),
        c(t.v2[0], t.v2[1], t.v2[2]);
    const glm::dvec3 n = glm::cross(b - a, c - a);
    const double size = std::sqrt(0.5 * glm::length(n));
    const glm::dvec3 centroid = (a + b + c) / 3.0;
    consider({a, b, c, (a + b) / 2.0, (b + c) / 2.0, (c + a) / 2.0, centroid}, 0.0, size, a, n,
             LC_INVALID, i, centroid, false);
  }
  if (!(worst > 1.0 / 256)) return "";
  char where[160], buf[800];
  if (worst_sphere)
    std::snprintf(where, sizeof where, "a sphere light of radius %.2g at (%.6g, %.6g, %.6g)",
                  worst_s, worst_at.x, worst_at.y, worst_at.z);
  else
    std::snprintf(where, sizeof where,
                  "an emissive triangle of size %.2g (the square root of its area) at (%.6g, "
                  "%.6g, %.6g)",
                  worst_s, worst_at.x, worst_at.y, worst_at.z);
  char distance[64];
  if (worst_h > 0)
    std::snprintf(distance, sizeof distance, "lies %.2g from", worst_h);
  else
    std::snprintf(distance, sizeof distance, "touches");
  std::snprintf(buf, sizeof buf,
                "in float precision, %s %s a surface whose rays leave offset by up to %.2g, "
                "%.2g of the light's size: the light it casts there may be biased by about a "
                "tenth of that (a square lamp of side 0.006 at 0.003 over a floor of +-60 "
                "rendered 0.12%% bright); use --precision double, or a larger lamp or one "
                "farther from the surface",
                where, distance, worst_m, worst);
  return buf;
}

bool light_traced_caustics(const Scene& scene) {
  if (!scene.integrator.caustics || scene.integrator.type != IntegratorType::Path) return false;
  const auto delta = [&scene](int mi) {
    return mi >= 0 && static_cast<std::size_t>(mi) < scene.materials.size() &&
           scatters_by_delta(scene.materials[static_cast<std::size_t>(mi)]);
  };
  return std::any_of(scene.spheres.begin(), scene.spheres.end(),
                     [&](const Sphere& s) { return delta(s.material); }) ||
         std::any_of(scene.triangles.begin(), scene.triangles.end(),
                     [&](const Triangle& t) { return delta(t.material); });
}

PackedScene pack_scene(const Scene& scene, const PackedScene* previous, bool* bvh_reused) {
  // what the kernel's 32-bit indices can reach, before anything is built: the BVH's leaf blocks
  // (one per primitive at worst) and the texels (a texture's offset and offset + y w + x are
  // lc_uint; the memory checks refuse such sizes on most devices, not on a large host's PoCL)
  const std::uint64_t prims = std::uint64_t(scene.triangles.size()) + scene.spheres.size();
  if (prims > std::uint64_t(LC_BVH_LEAF_FIRST_MASK) + 1)
    throw Error(scene_detail::in_file(
        scene.path, std::to_string(prims) + " primitives, more than the BVH can reference (" +
                        std::to_string(std::uint64_t(LC_BVH_LEAF_FIRST_MASK) + 1) +
                        "): reduce the number of triangles and spheres"));
  std::uint64_t texels = 0;
  for (const Texture& t : scene.textures)
    texels += std::uint64_t(t.width) * std::uint64_t(t.height);
  if (texels > std::uint64_t(UINT32_MAX))
    throw Error(scene_detail::in_file(
        scene.path, "the textures hold " + std::to_string(texels) +
                        " texels, more than the kernel's 32-bit texel offsets reach (" +
                        std::to_string(std::uint64_t(UINT32_MAX)) +
                        "): reduce the textures' resolution"));
  PackedScene p;
  lc_params& P = p.params;
  P.camera = pack_camera(scene.camera, scene.film.width, scene.film.height);
  P.width = static_cast<lc_uint>(scene.film.width);
  P.height = static_cast<lc_uint>(scene.film.height);
  P.seed = scene.integrator.seed;
  P.max_depth = static_cast<lc_uint>(scene.integrator.max_depth);
  P.rr_depth = static_cast<lc_uint>(scene.integrator.rr_depth);
  P.integrator = static_cast<lc_uint>(scene.integrator.type);
  P.filter = static_cast<lc_uint>(scene.film.filter.type);
  P.filter_radius = static_cast<float>(scene.film.filter.radius);
  P.env_light = -1;
  P.flags =
      (scene.integrator.mis ? 0u : LC_FLAG_NO_MIS) |
      (scene.integrator.caustics && scene.integrator.type == IntegratorType::Path ? LC_FLAG_CAUSTICS
                                                                                  : 0u);
  P.sampler = static_cast<lc_uint>(scene.integrator.sampler);
  static_assert(limits::kMaxDielectricSplits == LC_MAX_SPLITS,
                "the kernel's stack of waiting branches holds the most splits a scene may ask");
  P.splits = scene.integrator.type == IntegratorType::Path
                 ? static_cast<lc_uint>(scene.integrator.dielectric_splits)
                 : 0u;
  // a positive clamp stays positive in float (0 is off)
  P.clamp = scene.integrator.clamp > 0
                ? std::max(static_cast<float>(scene.integrator.clamp), FLT_MIN)
                : 0.0f;
  P.ao_distance = scene.integrator.ao_distance > 0
                      ? static_cast<float>(scene.integrator.ao_distance)
                      : INFINITY;

  if (scene.materials.empty() && (!scene.spheres.empty() || !scene.triangles.empty()))
    throw Error(scene_detail::in_file(scene.path, "shapes need at least one material"));
  // The texture headers: one per texture, mapped by default (an environment map's, and the
  // index of a material that maps its texture so), then one per other (texture, mapping) a
  // material asks for, on the same texels: an image is held once however it is mapped.
  std::vector<lc_uint> texel_offset;
  {
    std::uint64_t at = 0;
    for (const Texture& t : scene.textures) {
      texel_offset.push_back(static_cast<lc_uint>(at));
      at += t.rgba.size() / 4;  // (as the texels are packed, below)
    }
    const Material plain;
    for (std::size_t i = 0; i < scene.textures.size(); ++i)
      p.textures.push_back(texture_header(scene.textures[i], texel_offset[i], plain));
  }
  std::map<std::vector<unsigned char>, int> mapped_headers;  // header bytes -> index
  // per material: its mapping as the device reads it, and its texture's header (or -1)
  std::vector<Material> mappings;
  std::vector<int> material_texture;
  for (const Material& m : scene.materials) {
    lc_material d;
    std::fill(std::begin(d.p.words), std::end(d.p.words), 0.0f);
    put3(d.emission, m.emission);
    d.type = static_cast<lc_uint>(m.type);
    Material device = m;
    const std::size_t t = static_cast<std::size_t>(m.albedo_texture);
    const Material mapping = device_texture_mapping(m, scene.textures.size());
    if (!mapping.default_albedo_mapping()) {
      const lc_texture h = texture_header(scene.textures[t], texel_offset[t], mapping);
      const unsigned char* b = reinterpret_cast<const unsigned char*>(&h);
      auto [it, added] = mapped_headers.insert(
          {std::vector<unsigned char>(b, b + sizeof h), static_cast<int>(p.textures.size())});
      if (added) p.textures.push_back(h);
      device.albedo_texture = it->second;
    }
    mappings.push_back(mapping);
    material_texture.push_back(device.albedo_texture);
    scene_detail::material_type_def(m.type).pack(device, d.p);
    p.materials.push_back(d);
  }

  // emissive shapes become area lights, in scene order; pack_lights adds the scene's lights
  std::vector<double> power;
  auto add_light = [&](const lc_light& l, double pw) {
    p.lights.push_back(l);
    power.push_back(std::max(0.0, pw));
    return static_cast<lc_uint>(p.lights.size() - 1);
  };

  // as large as they will be: growing by doubling copied a 10^6-triangle mesh's arrays about
  // twice over, into fresh pages, at every set_scene (a camera move included)
  p.spheres.reserve(scene.spheres.size());
  p.triangles.reserve(scene.triangles.size());
  p.tri_attrs.reserve(scene.triangles.size());
  for (const Sphere& s : scene.spheres) {
    lc_sphere d{};
    put3(d.center, s.center);
    d.radius = static_cast<float>(s.radius);
    d.material = static_cast<lc_uint>(s.material);
    d.light = LC_INVALID;
    const Material& m = scene.materials[s.material];
    d.flags = m.albedo_texture >= 0 ? LC_SPHERE_TEXTURED : 0u;
    d.texture =
        m.albedo_texture >= 0 ? static_cast<lc_uint>(material_texture[s.material]) : LC_INVALID;
    if (m.emissive()) {
      lc_light l{};
      l.type = LC_LIGHT_SPHERE;
      l.p.sphere.sphere = static_cast<lc_uint>(p.spheres.size());
      put3(l.p.sphere.radiance, m.emission);
      double area = static_cast<float>(4 * M_PI * s.radius * s.radius);
      d.light = add_light(l, luminance(m.emission) * M_PI * area);
    }
    p.spheres.push_back(d);
  }

  for (size_t i = 0; i < scene.triangles.size(); ++i) {
    const Triangle& t = scene.triangles[i];
    glm::dvec3 v[3] = {scene.positions[t.v[0]], scene.positions[t.v[1]], scene.positions[t.v[2]]};
    glm::dvec3 cr = glm::cross(v[1] - v[0], v[2] - v[0]);
    double area = 0.5 * glm::length(cr);
    if (!finite3(v[0]) || !finite3(v[1]) || !finite3(v[2]) || !(area > 0) || !std::isfinite(area)) {
      ++p.skipped_triangles;
      continue;
    }
    lc_triangle d{};
    put3(d.v0, v[0]);
    put3(d.v1, v[1]);
    put3(d.v2, v[2]);
    // collinear after rounding to float (it is never hit, but it may emit): the normal before
    if (!set_triangle_normal(d)) put_normal(d, cr / (2 * area));
    d.material = static_cast<lc_uint>(t.material);
    d.light = LC_INVALID;
    lc_triangle_attr a{};
    bool has_n = t.n[0] >= 0 && t.n[1] >= 0 && t.n[2] >= 0;
    bool has_uv = t.uv[0] >= 0 && t.uv[1] >= 0 && t.uv[2] >= 0;
    // The uvs in the texture space of the material's texture (uv * scale + offset, in double:
    // affine, so the kernel's barycentric interpolation of the mapped uvs is the mapping of the
    // interpolated ones; a triangle without uvs has (0, 0), (1, 0), (0, 1), the barycentrics
    // the kernel reads otherwise), then less the whole periods (repeat 1, mirror 2; clamp none)
    // of their smallest: the lookup reads the same texels, and the kernel's float interpolation
    // keeps the fraction (uvs near 1e7 lost it: a texture there rendered as blocks, 64 standard
    // errors off the reference; uvs near 1e5 under a scale of 1.5, mapped in the kernel, read
    // texels up to one off). The kernel applies no scale or offset to triangles' uvs.
    const Material& mapping = mappings[t.material];
    const bool mapped = !mapping.default_albedo_mapping();
    glm::dvec2 uv[3] = {};
    if (has_uv || mapped) {
      for (int k = 0; k < 3; ++k) {
        uv[k] = has_uv ? scene.uvs[t.uv[k]] : glm::dvec2(k == 1 ? 1.0 : 0.0, k == 2 ? 1.0 : 0.0);
        if (mapped) uv[k] = uv[k] * mapping.albedo_uv_scale + mapping.albedo_uv_offset;
      }
      has_uv = true;
      glm::dvec2 lo = glm::min(uv[0], glm::min(uv[1], uv[2]));
      const TextureWrap wrap[2] = {mapping.albedo_wrap_u, mapping.albedo_wrap_v};
      for (int c = 0; c < 2; ++c) {
        const double period = wrap_period(wrap[c]);
        if (period > 0 && std::isfinite(lo[c])) {
          const double whole = period * std::floor(lo[c] / period);
          for (int k = 0; k < 3; ++k) uv[k][c] -= whole;
        }
      }
    }
    // Normals far from unit length (set directly: Scene.normals, from Python) scaled, all three
    // by one power of two, their largest component then in [1, 2): the interpolation's direction
    // is the same, and normals as short as 1e-50 no longer became 0 in float, where the kernel
    // then shaded with the geometric normal and the reference, in double, with theirs. (Unit
    // normals, the loaders' and the builder's, are packed as they are.)
    // (each component by ldexp: 2^-ilogb(m) itself is infinite for a subnormal m)
    int n_exp = 0;
    if (has_n) {
      double m = 0;
      for (int k = 0; k < 3; ++k) m = std::max(m, scene_detail::max_abs(scene.normals[t.n[k]]));
      if (m > 0 && std::isfinite(m) && (m < 0x1p-32 || m > 0x1p32)) n_exp = -std::ilogb(m);
    }
    for (int k = 0; k < 3; ++k) {
      if (has_n) {
        const glm::dvec3& n = scene.normals[t.n[k]];
        put3(a.n + 3 * k,
             glm::dvec3(std::ldexp(n.x, n_exp), std::ldexp(n.y, n_exp), std::ldexp(n.z, n_exp)));
      }
      if (has_uv) {
        a.uv[2 * k] = static_cast<float>(uv[k].x);
        a.uv[2 * k + 1] = static_cast<float>(uv[k].y);
      }
    }
    d.flags = (has_n ? LC_TRI_HAS_NORMALS : 0u) | (has_uv ? LC_TRI_HAS_UVS : 0u);
    a.source_index = static_cast<lc_uint>(i);
    const Material& m = scene.materials[t.material];
    if (m.emissive()) {
      lc_light l{};
      l.type = LC_LIGHT_TRIANGLE;
      l.p.triangle.triangle = static_cast<lc_uint>(p.triangles.size());
      put3(l.p.triangle.radiance, m.emission);
      l.p.triangle.area = static_cast<float>(area);
      d.light = add_light(l, luminance(m.emission) * M_PI * area);
    }
    p.triangles.push_back(d);
    p.tri_attrs.push_back(a);
  }
  if (p.skipped_triangles > 0)
    scene_detail::warn(
        scene_detail::in_file(scene.path, "skipped " + std::to_string(p.skipped_triangles) +
                                              " degenerate or non-finite triangle(s)"));
  // integrator.caustics: no surface that can scatter by a delta lobe (MaterialTypeDef::delta: a
  // mirror, smooth glass, a rough dielectric of ior 1), no caustic path: the kernel is built and
  // run without light paths
  if (P.flags & LC_FLAG_CAUSTICS) {
    auto delta = [&scene](lc_uint mi) { return scatters_by_delta(scene.materials[mi]); };
    bool any = false;
    for (const lc_sphere& sp : p.spheres) any = any || delta(sp.material);
    for (const lc_triangle& t : p.triangles) any = any || delta(t.material);
    if (!any) P.flags &= ~LC_FLAG_CAUSTICS;
  }
  // light paths reach a pixel through its filter only: a filter of a tiny radius (accepted, a
  // near-delta filter) takes almost none of them, and makes the few it takes huge (its density
  // 1/(4 r^2) or more), which the non-finite rule drops: the caustics vanished from an image that
  // looked complete (the film review)
  if ((P.flags & LC_FLAG_CAUSTICS) && scene.film.filter.radius < 0.05)
    scene_detail::warn(scene_detail::in_file(
        scene.path, "integrator.caustics with a filter radius of " +
                        scene_detail::format_number(scene.film.filter.radius) +
                        " pixels: light paths reach a pixel through its filter only, so few "
                        "of them count and the caustics are faint or missing; use a radius of at "
                        "least 0.5"));

  const bool reuse = previous && same_geometry(*previous, p);
  if (bvh_reused) *bvh_reused = reuse;
  if (reuse) {
    p.nodes = previous->nodes;
    p.leaves = previous->leaves;
    p.bvh_stats = previous->bvh_stats;
    std::copy(previous->bounds_min, previous->bounds_min + 3, p.bounds_min);
    std::copy(previous->bounds_max, previous->bounds_max + 3, p.bounds_max);
  } else {
    bvh::Bvh bvh = bvh::build(p.triangles, p.spheres);
    p.nodes = std::move(bvh.nodes);
    p.leaves = std::move(bvh.leaves);
    p.bvh_stats = bvh.stats;
    std::copy(bvh.bmin, bvh.bmin + 3, p.bounds_min);
    std::copy(bvh.bmax, bvh.bmax + 3, p.bounds_max);
  }

  warn_camera_precision(scene, scene.camera, p);
  p.area_power = power;  // (repack_camera builds the light table again from them)
  pack_lights(scene, p, std::move(power), environment_radius(scene.camera, p));
  // a light-transport integrator with nothing that emits renders a black image: said, not
  // silently written
  for (const std::string& note : scene_detail::light_notes(scene)) scene_detail::warn(note);
  // (not with every light skipped: "no light left", below, says more)
  if (!p.lights.empty() || !scene.lights.empty())
    for (const std::string& note : scene_detail::point_light_notes(scene)) scene_detail::warn(note);
  for (const std::string& note : scene_detail::radiance_notes(scene)) scene_detail::warn(note);

  // reserved: a large array's capacity is the block it holds (and a CPU device shares)
  p.texels.reserve(static_cast<std::size_t>(texels));
  for (const Texture& t : scene.textures) {  // (their headers are made with the materials)
    for (size_t i = 0; i + 3 < t.rgba.size(); i += 4)
      p.texels.push_back({{t.rgba[i], t.rgba[i + 1], t.rgba[i + 2], t.rgba[i + 3]}});
  }

  P.num_triangles = static_cast<lc_uint>(p.triangles.size());
  P.num_spheres = static_cast<lc_uint>(p.spheres.size());
  P.num_lights = static_cast<lc_uint>(p.lights.size());
  P.num_nodes = static_cast<lc_uint>(p.nodes.size());
  // emissive shapes were its only lights, and packing left none (degenerate or non-finite
  // triangles skipped, above): the scene's light notes, read before packing, said nothing, and
  // the image was black after a warning about skipped triangles alone
  if (p.lights.empty() && scene.lights.empty() && !is_aov(scene.integrator.type) &&
      scene_detail::light_notes(scene).empty())  // (else the note of no light at all was given)
    scene_detail::warn(
        scene_detail::in_file(scene.path,
                              "the scene has no light left (its emissive shapes were all skipped: "
                              "degenerate, non-finite or of no area): the image is black"));
  return p;
}

CameraPacking repack_camera(const Scene& scene, const PackedScene& packed, const Camera& camera) {
  CameraPacking c;
  c.params = packed.params;
  c.params.camera = pack_camera(camera, scene.film.width, scene.film.height);
  warn_camera_precision(scene, camera, packed);
  // the light table follows the camera only through environment lights' power, and only when
  // the camera's distance to its look-at bounds their radius: built again then (an environment
  // map's texel CDF included, the same bits), as pack_scene builds it, from the area lights' kept
  // powers
  const double radius = environment_radius(camera, packed);
  if (packed.params.env_light < 0 || radius == environment_radius(scene.camera, packed)) return c;
  PackedScene t;
  t.params = c.params;
  t.lights.assign(packed.lights.begin(),
                  packed.lights.begin() + static_cast<std::ptrdiff_t>(packed.area_power.size()));
  pack_lights(scene, t, packed.area_power, radius);
  const bool same =
      t.lights.size() == packed.lights.size() && t.light_cdf.size() == packed.light_cdf.size() &&
      std::memcmp(t.lights.data(), packed.lights.data(), t.lights.size() * sizeof(lc_light)) == 0 &&
      std::memcmp(t.light_cdf.data(), packed.light_cdf.data(),
                  t.light_cdf.size() * sizeof(float)) == 0;
  if (same) return c;
  c.lights_changed = true;
  c.lights = std::move(t.lights);
  c.light_cdf = std::move(t.light_cdf);
  return c;
}

}  // namespace lucent::render_detail

namespace lucent {

const char* precision_name(Precision p) {
  // (Precision(7) was "float")
  if (p == Precision::Float) return "float";
  if (p == Precision::Double) return "double";
  throw Error("precision_name: Precision must be Float or Double, got " +
              std::to_string(static_cast<int>(p)));
}

Precision parse_precision(const std::string& text, const std::string& what) {
  if (text == "float") return Precision::Float;
  if (text == "double") return Precision::Double;
  throw Error(what + ": unknown precision '" + text + "' (expected float or double)");
}

}  // namespace lucent
