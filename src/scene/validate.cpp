// The value checks of a scene (validate.hpp): one place for every check, shared by the JSON
// loader and SceneBuilder.
#include "scene/validate.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "core/text.hpp"
#include "lucent/error.hpp"
#include "lucent/types.hpp"
#include "scene/loaders.hpp"
#include "scene/material_type.hpp"

namespace lucent::scene_detail {

std::string in_file(const std::string& file, const std::string& what) {
  return file.empty() ? what : file + ": " + what;
}

std::string pointer_key(const std::string& key) {
  std::string out;
  for (char c : key) out += c == '~' ? "~0" : c == '/' ? "~1" : std::string(1, c);
  return out;
}

void Reporter::fail(const std::string& what) const {
  const std::string& ptr = pointer_.empty() ? std::string("/") : pointer_;
  throw Error(in_file(file_, ptr + ": " + what));
}

std::string format_number(double v) {
  // six significant digits where they give the value back, else as many as it takes (at most
  // 17): an ior of 20.0000001 was "must be in [0.05, 20], got 20". In the "C" locale, as
  // ostream's classic one was ("got 180,5" after a German setlocale)
  const io::CNumbers c_numbers;
  return io::shortest_real(v, 6);
}

// ---------------------------------------------------------------------------------------------

void fail_range(const Reporter& at, IntRange range, const std::string& shown) {
  at.fail("must be in [" + std::to_string(range.lo) + ", " + std::to_string(range.hi) + "], got " +
          shown);
}

void check_range(const Reporter& at, long long v, IntRange range) {
  if (v < range.lo || v > range.hi) fail_range(at, range, std::to_string(v));
}

double check_finite(const Reporter& at, double v) {
  if (!std::isfinite(v)) at.fail("must be a finite number, got " + format_number(v));
  // the device stores floats: a larger value would become infinite there
  if (std::abs(v) > FLT_MAX)
    at.fail("must fit in a float (magnitude at most 3.4e38), got " + format_number(v));
  return v;
}

void check_positive(const Reporter& at, double v) {
  if (!(check_finite(at, v) > 0)) at.fail("must be > 0, got " + format_number(v));
}

void check_non_negative(const Reporter& at, double v) {
  if (check_finite(at, v) < 0) at.fail("must be >= 0, got " + format_number(v));
}

void check_between(const Reporter& at, double v, double lo, double hi) {
  if (check_finite(at, v) < lo || v > hi)
    at.fail("must be in [" + format_number(lo) + ", " + format_number(hi) + "], got " +
            format_number(v));
}

void check_point(const Reporter& at, const glm::dvec3& v) {
  for (int i = 0; i < 3; ++i) check_finite(at.at(i), v[i]);
}

double max_abs(const glm::dvec3& v) {
  return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
}

glm::dvec3 unit(const glm::dvec3& v) {
  const double m = max_abs(v);
  if (!(m > 0) || !std::isfinite(m)) return v;
  const int e = std::ilogb(m);
  return glm::normalize(glm::dvec3(std::ldexp(v.x, -e), std::ldexp(v.y, -e), std::ldexp(v.z, -e)));
}

std::string beyond_geometry_range(const std::string& what) {
  return what + " is beyond lucent's geometry range (coordinates of magnitude at most " +
         format_number(limits::kMaxCoordinate) +
         ", where the kernel's float intersection arithmetic still holds)";
}

void check_position(const Reporter& at, const glm::dvec3& v) {
  check_point(at, v);
  for (int i = 0; i < 3; ++i)
    if (std::abs(v[i]) > limits::kMaxCoordinate)
      at.at(i).fail(beyond_geometry_range(format_number(v[i])));
}

void check_colour(const Reporter& at, const glm::dvec3& c) {
  for (int i = 0; i < 3; ++i) check_non_negative(at.at(i), c[i]);
}

void check_nonzero(const Reporter& at, const glm::dvec3& v) {
  check_point(at, v);
  if (max_abs(v) == 0) at.fail("must be a non-zero vector");
}

void check_scale(const Reporter& at, const glm::dvec3& s) {
  if (s.x == s.y && s.y == s.z)
    check_non_negative(at, s.x);
  else
    check_colour(at, s);
}

void check_affine(const Reporter& at, const glm::dmat4& m) {
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)  // glm: m[column][row]; only the transformed points must be floats
      if (!std::isfinite(m[c][r]))
        at.at(r).at(c).fail("must be a finite number, got " + format_number(m[c][r]));
  if (m[0][3] != 0 || m[1][3] != 0 || m[2][3] != 0 || m[3][3] != 1)
    at.fail("the last row must be [0, 0, 0, 1] (affine transforms only)");
  // (scale-free: the determinant alone underflowed for a uniform scale of 1e-110)
  if (!(std::abs(unit_determinant(glm::dmat3(m))) > 1e-12)) at.fail("must be invertible");
}

namespace {

/// `m`'s columns made unit length, and the lengths they had (0 for a zero column).
glm::dmat3 unit_columns(const glm::dmat3& m, glm::dvec3& lengths) {
  glm::dmat3 unit(0.0);
  for (int c = 0; c < 3; ++c) {
    const double largest = max_abs(m[c]);  // divided first: the length of (1e-200, 0, 0) underflows
    lengths[c] = largest == 0 ? 0 : largest * glm::length(m[c] / largest);
    if (largest != 0) unit[c] = glm::normalize(m[c] / largest);
  }
  return unit;
}

}  // namespace

double unit_determinant(const glm::dmat3& m) {
  glm::dvec3 lengths;
  const glm::dmat3 unit = unit_columns(m, lengths);
  return lengths.x == 0 || lengths.y == 0 || lengths.z == 0 ? 0 : glm::determinant(unit);
}

glm::dmat3 normal_transform(const glm::dmat3& m) {
  // m = U diag(lengths), so its inverse transpose is U^-T diag(1 / lengths): U (unit columns,
  // determinant above 1e-12) inverts without overflow, and diag(shortest / lengths) is the second
  // factor up to a positive one, with no entry above 1 (glm's inverse of m itself divides by a
  // determinant that underflows for a scale of 1e-110, or of (1, 1, 1e300))
  glm::dvec3 lengths;
  const glm::dmat3 unit = unit_columns(m, lengths);
  const double shortest = std::min({lengths.x, lengths.y, lengths.z});
  glm::dmat3 diagonal(0.0);
  for (int c = 0; c < 3; ++c) diagonal[c][c] = shortest / lengths[c];
  return glm::transpose(glm::inverse(unit)) * diagonal;
}

void check_texture_index(const Reporter& at, int index, std::size_t textures, bool optional) {
  if (optional && index == -1) return;
  if (index < 0 || static_cast<std::size_t>(index) >= textures)
    at.fail("must be the index of a texture of the scene (" + std::to_string(textures) +
            (optional ? "), or -1, got " : "), got ") + std::to_string(index));
}

void check_light_type(const Reporter& at, LightType type) {
  if (!find_entry(type)) at.fail("unknown light type " + std::to_string(static_cast<int>(type)));
  if (is_shape_light(type))
    at.fail(std::string("'") + type_name(type) +
            "' lights are emissive shapes, not entries of \"lights\": give a shape a material "
            "with \"emission\"");
}

std::string scene_light_names() {
  std::string list;
  for (const TypeEntry<LightType>& e : TypeList<LightType>::entries)
    if (!is_shape_light(e.value)) list += std::string(list.empty() ? "" : ", ") + e.name;
  return list;
}

namespace {

bool finite(const glm::dvec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

/// A value of a registry enum that no entry has (an integer cast in code).
template <class E>
void check_type(const Reporter& at, E value) {
  if (!find_entry(value))
    at.fail(std::string("unknown ") + TypeList<E>::what + " " +
            std::to_string(static_cast<int>(value)) + " (expected one of: " + type_names<E>() +
            ")");
}

}  // namespace

// ---------------------------------------------------------------------------------------------

namespace {
constexpr double kMaxApertureRatio = 100;  ///< lens radius / focus distance
}  // namespace

void validate_camera(const Camera& c, const Reporter& at) {
  check_position(at.at("position"), c.position);
  check_point(at.at("look_at"), c.look_at);  // aimed at, not intersected: not in the range
  check_nonzero(at.at("up"), c.up);
  if (!(check_finite(at.at("fov"), c.fov_degrees) > 0 && c.fov_degrees < 180))
    at.at("fov").fail("must be in (0, 180) degrees, got " + format_number(c.fov_degrees));
  check_finite(at.at("roll"), c.roll_degrees);
  check_non_negative(at.at("aperture"), c.aperture);
  check_non_negative(at.at("focus_distance"), c.focus_distance);
  glm::dvec3 forward = c.look_at - c.position;
  if (max_abs(forward) == 0) at.at("look_at").fail("must differ from the camera position");
  if (glm::length(glm::cross(unit(forward), unit(c.up))) < 1e-9)
    at.at("up").fail("must not be parallel to the viewing direction");
  // The kernel aims a lens ray at the focal plane in float from its point on the lens: from a
  // lens 1e8 times wider than the focus distance the aim is off by more than the scene, and
  // the geometry vanished from the image without a word. 100 times keeps it within 1e-5 of the
  // focus distance (rays up to 89.4 degrees off the axis: a blur of the whole image already).
  const double focus = c.focus_distance > 0 ? c.focus_distance : glm::length(forward);
  if (c.aperture > kMaxApertureRatio * focus)
    at.at("aperture")
        .fail("must be at most " + format_number(kMaxApertureRatio) +
              " times the focus distance (" + format_number(focus) + "), got " +
              format_number(c.aperture));
}

void validate_film(const Film& f, const Reporter& at) {
  check_range(at.at("width"), f.width, rules::kImageSize);
  check_range(at.at("height"), f.height, rules::kImageSize);
  Reporter filter = at.at("filter");
  check_type(filter.at("type"), f.filter.type);
  check_positive(filter.at("radius"), f.filter.radius);
  if (f.filter.radius > limits::kMaxFilterRadius)
    filter.at("radius").fail("must be <= " + format_number(limits::kMaxFilterRadius) + " pixels");
  if (f.transfer != Transfer::Srgb && f.transfer != Transfer::Gamma &&
      f.transfer != Transfer::Linear)
    at.at("transfer").fail("unknown transfer " + std::to_string(static_cast<int>(f.transfer)));
  check_positive(at.at("gamma"), f.gamma);
  check_finite(at.at("exposure"), f.exposure);
  if (f.tonemap != ToneMap::Clamp && f.tonemap != ToneMap::Reinhard && f.tonemap != ToneMap::Aces)
    at.at("tonemap").fail("unknown tone map " + std::to_string(static_cast<int>(f.tonemap)));
}

void validate_integrator(const Integrator& in, const Reporter& at) {
  check_type(at.at("type"), in.type);
  check_range(at.at("max_depth"), in.max_depth, rules::kDepth);
  check_range(at.at("rr_depth"), in.rr_depth, rules::kDepth);
  check_range(at.at("spp"), in.spp, rules::kSpp);
  check_non_negative(at.at("ao_distance"), in.ao_distance);  // 0: unbounded
  check_type(at.at("sampler"), in.sampler);
  check_non_negative(at.at("clamp"), in.clamp);  // 0: off
  check_range(at.at("dielectric_splits"), in.dielectric_splits, rules::kSplits);
}

void validate_texture(const Texture& t, const Reporter& at) {
  if (t.width < 1) at.at("width").fail("must be >= 1, got " + std::to_string(t.width));
  if (t.height < 1) at.at("height").fail("must be >= 1, got " + std::to_string(t.height));
  std::size_t want = std::size_t(4) * std::size_t(t.width) * std::size_t(t.height);
  if (t.rgba.size() != want)
    at.at("rgba").fail("must hold 4 x " + std::to_string(t.width) + " x " +
                       std::to_string(t.height) + " = " + std::to_string(want) + " floats, got " +
                       std::to_string(t.rgba.size()));
  for (std::size_t i = 0; i < t.rgba.size(); ++i)  // the place is made only for a bad texel
    if (!(std::isfinite(t.rgba[i]) && t.rgba[i] >= 0))
      check_non_negative(at.at("rgba").at(i), t.rgba[i]);
}

void check_texture_mapping(const Material& m, const Reporter& at) {
  const TextureWrap wrap[2] = {m.albedo_wrap_u, m.albedo_wrap_v};
  for (int k = 0; k < 2; ++k) {
    if (wrap[k] != TextureWrap::Repeat && wrap[k] != TextureWrap::Clamp &&
        wrap[k] != TextureWrap::Mirror)
      at.at("wrap").at(k).fail("unknown wrap mode " + std::to_string(static_cast<int>(wrap[k])) +
                               " (expected one of: repeat, clamp, mirror)");
    const double s = check_finite(at.at("uv_scale").at(k), m.albedo_uv_scale[k]);
    if (!(std::fabs(s) >= limits::kMinUvScale && std::fabs(s) <= limits::kMaxUvScale))
      at.at("uv_scale")
          .at(k)
          .fail("must be between " + format_number(limits::kMinUvScale) + " and " +
                format_number(limits::kMaxUvScale) + " in magnitude (either sign), got " +
                format_number(s));
    const double o = check_finite(at.at("uv_offset").at(k), m.albedo_uv_offset[k]);
    if (!(std::fabs(o) <= limits::kMaxUvOffset))
      at.at("uv_offset")
          .at(k)
          .fail("must be at most " + format_number(limits::kMaxUvOffset) + " in magnitude, got " +
                format_number(o));
  }
}

void validate_material(const Material& m, const std::vector<Texture>& textures,
                       const Reporter& at) {
  if (m.name.empty()) at.fail("material names must not be empty");
  check_type(at.at("type"), m.type);
  check_colour(at.at("emission"), m.emission);
  check_texture_index(at.at("albedo").at("texture"), m.albedo_texture, textures.size(), true);
  check_texture_mapping(m, at.at("albedo"));
  // the type's parameters, by its parameter table (src/scene/materials/<file>.cpp)
  const MaterialTypeDef& def = material_type_def(m.type);
  for (const MaterialParam& param : def.params) {
    const Reporter p = at.at(param.key);
    switch (param.kind) {
      case MaterialParam::Colour:
      case MaterialParam::ColourOrTexture:
        check_colour(p, m.*param.colour);
        break;
      case MaterialParam::UnitInterval:
        check_between(p, m.*param.number, 0, 1);
        break;
      case MaterialParam::Ior:
        check_between(p, m.*param.number, MaterialParam::kMinIor, MaterialParam::kMaxIor);
        break;
    }
  }
  if (def.check) def.check(m, textures, at);
}

void validate_light(const Light& l, std::size_t textures, const Reporter& at) {
  check_light_type(at.at("type"), l.type);
  switch (l.type) {
    case LightType::Point:
      check_position(at.at("position"), l.position);
      check_colour(at.at("intensity"), l.intensity);
      break;
    case LightType::Environment:
      check_colour(at.at("radiance"), l.radiance);
      break;
    case LightType::EnvironmentMap:
      check_texture_index(at.at("texture"), l.texture, textures, false);
      check_scale(at.at("scale"), l.radiance);
      break;
    case LightType::Sphere:  // emissive shapes: refused by check_light_type
    case LightType::Triangle:
      break;
  }
}

namespace {

/// The largest coordinate magnitude of a sphere's points.
double sphere_reach(const glm::dvec3& c, double r) { return max_abs(c) + r; }

void check_sphere_reach(const Reporter& at, const glm::dvec3& c, double r) {
  if (sphere_reach(c, r) > limits::kMaxCoordinate)
    at.at("radius").fail(beyond_geometry_range("the sphere's farthest coordinate, " +
                                               format_number(sphere_reach(c, r)) + ","));
}

}  // namespace

void validate_sphere(const SphereShape& s, const Reporter& at) {
  check_position(at.at("center"), s.center);
  check_positive(at.at("radius"), s.radius);
  check_sphere_reach(at, s.center, s.radius);
}

void validate_mesh(const MeshShape& m, const Reporter& at) {
  const std::size_t n = m.positions.size();
  if (n == 0) at.at("positions").fail("must be a non-empty array of [x, y, z]");
  // (the places are made only for a bad element: meshes may be large)
  for (std::size_t i = 0; i < n; ++i)
    if (!finite(m.positions[i])) check_point(at.at("positions").at(i), m.positions[i]);
  // (an empty list made a shape of no triangle without a word)
  if (m.indices.empty() || m.indices.size() % 3 != 0)
    at.at("indices").fail("must be a non-empty array whose length is a multiple of 3");
  for (std::size_t i = 0; i < m.indices.size(); ++i)
    if (m.indices[i] < 0 || static_cast<std::size_t>(m.indices[i]) >= n)
      check_range(at.at("indices").at(i), m.indices[i], rules::vertex_index(n));
  if (!m.normals.empty() && m.normals.size() != n)
    at.at("normals").fail("must have one entry per position (" + std::to_string(n) + "), got " +
                          std::to_string(m.normals.size()));
  for (std::size_t i = 0; i < m.normals.size(); ++i)
    if (!finite(m.normals[i])) check_point(at.at("normals").at(i), m.normals[i]);
  if (!m.uvs.empty() && m.uvs.size() != n)
    at.at("uvs").fail("must have one entry per position (" + std::to_string(n) + "), got " +
                      std::to_string(m.uvs.size()));
  for (std::size_t i = 0; i < m.uvs.size(); ++i)
    if (!finite(glm::dvec3(m.uvs[i], 0)))
      for (int c = 0; c < 2; ++c) check_finite(at.at("uvs").at(i).at(c), m.uvs[i][c]);
  check_affine(at.at("transform"), m.transform);
}

namespace {

// A vector the device can hold (a texture coordinate, a shading normal): finite, and within
// float range.
template <int N>
bool fits_float(const glm::vec<N, double>& v) {
  for (int c = 0; c < N; ++c)
    if (!(std::abs(v[c]) <= FLT_MAX)) return false;  // NaN too
  return true;
}

// A triangle's normal or uv indices: three indices, or -1 for all three (none).
bool all_or_none(const int (&ix)[3]) {
  const bool all = ix[0] >= 0 && ix[1] >= 0 && ix[2] >= 0;
  return all || (ix[0] == -1 && ix[1] == -1 && ix[2] == -1);
}

void check_all_or_none(const Reporter& at, const int (&ix)[3], const char* what) {
  if (!all_or_none(ix))
    at.fail("must be three indices of the scene's " + std::string(what) +
            " or -1 for all three (none), got (" + std::to_string(ix[0]) + ", " +
            std::to_string(ix[1]) + ", " + std::to_string(ix[2]) + ")");
}

// The place of primitive `i` of a type: its shape entry's ("/shapes/3", "/shapes/1 (triangle
// 12)" for the 13th triangle of a mesh), else "/<list>/<i>".
std::string primitive_place(const Scene& s, ShapeType type, std::size_t i, const char* list,
                            const char* one) {
  for (std::size_t k = 0; k < s.shapes.size(); ++k) {
    const ShapeEntry& e = s.shapes[k];
    if (e.type != type || i < e.first || i >= e.first + e.count) continue;
    std::string place = "/shapes/" + std::to_string(k);
    if (e.count > 1 || type == ShapeType::Triangle)
      place += std::string(" (") + one + " " + std::to_string(i - e.first) + ")";
    return place;
  }
  return std::string("/") + list + "/" + std::to_string(i);
}

void check_index(const Reporter& at, int index, std::size_t size, const char* what) {
  if (index < 0 || static_cast<std::size_t>(index) >= size)
    at.fail("must index one of the scene's " + std::to_string(size) + " " + what + ", got " +
            std::to_string(index));
}

}  // namespace

void validate_scene(const Scene& s) {
  const std::string& file = s.path;
  validate_camera(s.camera, Reporter(file, "/camera"));
  {
    // any film size from 1 up: a film larger than a scene file's is refused by the memory
    // checks, with their own message (render/resources.hpp)
    const Reporter at(file, "/film");
    if (s.film.width < 1) at.at("width").fail("must be >= 1, got " + std::to_string(s.film.width));
    if (s.film.height < 1)
      at.at("height").fail("must be >= 1, got " + std::to_string(s.film.height));
    Film rest = s.film;
    rest.width = rest.height = 1;
    validate_film(rest, at);
  }
  validate_integrator(s.integrator, Reporter(file, "/integrator"));
  // sizes and texels, as SceneBuilder::add_texture and texture files require: set from Python
  // (Scene.textures), a NaN texel made every sample that read it non-finite (a black surface)
  // and a negative one negative light
  for (std::size_t i = 0; i < s.textures.size(); ++i)
    validate_texture(s.textures[i], Reporter(file, "/textures/" + std::to_string(i)));
  for (std::size_t i = 0; i < s.materials.size(); ++i) {
    // names only serve messages and the scene file's references: a nameless one is named by
    // its index
    Material m = s.materials[i];
    if (m.name.empty()) m.name = std::to_string(i);
    validate_material(m, s.textures, Reporter(file, "/materials").at(m.name));
  }
  for (std::size_t i = 0; i < s.lights.size(); ++i)
    validate_light(s.lights[i], s.textures.size(), Reporter(file, "/lights/" + std::to_string(i)));
  // one environment at most, as the loader and SceneBuilder say: with two, the escape light was
  // the last one and the first was seen only through light sampling (too dark)
  for (std::size_t i = 0, envs = 0; i < s.lights.size(); ++i)
    if (s.lights[i].type != LightType::Point && ++envs > 1)
      Reporter(file, "/lights/" + std::to_string(i)).fail("only one environment light is allowed");
  const std::size_t nm = s.materials.size();
  std::size_t never_hit = 0, first_never_hit = 0;
  for (std::size_t i = 0; i < s.spheres.size(); ++i) {
    // (a NaN or infinite centre or radius is allowed, with a warning, as a non-finite triangle
    // is: such a sphere is never hit, tests/test_stability_scene; a finite one beyond the
    // geometry range would vanish silently, so it is an error, and so is a radius <= 0, which the
    // loader refuses: from Python a negative one rendered the sphere inside out, its normals
    // pointing in)
    const Sphere& sp = s.spheres[i];
    if (!finite(sp.center) || !std::isfinite(sp.radius)) {
      if (never_hit++ == 0) first_never_hit = i;
    }
    const bool in_range = !(sphere_reach(sp.center, sp.radius) > limits::kMaxCoordinate);
    if (sp.material >= 0 && static_cast<std::size_t>(sp.material) < nm && in_range &&
        !(sp.radius <= 0))
      continue;
    const Reporter at(file, primitive_place(s, ShapeType::Sphere, i, "spheres", "sphere"));
    check_index(at.at("material"), sp.material, nm, "materials");
    if (sp.radius <= 0) at.at("radius").fail("must be > 0, got " + format_number(sp.radius));
    if (finite(sp.center) && std::isfinite(sp.radius)) check_sphere_reach(at, sp.center, sp.radius);
  }
  if (never_hit > 0)
    warn(in_file(file, primitive_place(s, ShapeType::Sphere, first_never_hit, "spheres", "sphere") +
                           ": " + std::to_string(never_hit) +
                           " sphere(s) with a non-finite centre or radius, never hit"));
  const std::size_t np = s.positions.size(), nn = s.normals.size(), nuv = s.uvs.size();
  for (std::size_t i = 0; i < s.triangles.size(); ++i) {
    const Triangle& t = s.triangles[i];
    // (the place is made only for a bad triangle: meshes may be large)
    bool ok = t.material >= 0 && static_cast<std::size_t>(t.material) < nm;
    const bool has_n = t.n[0] >= 0 && t.n[1] >= 0 && t.n[2] >= 0;
    const bool has_uv = t.uv[0] >= 0 && t.uv[1] >= 0 && t.uv[2] >= 0;
    for (int k = 0; k < 3; ++k) {
      ok = ok && t.v[k] >= 0 && static_cast<std::size_t>(t.v[k]) < np;
      ok = ok && (!has_n || static_cast<std::size_t>(t.n[k]) < nn);
      ok = ok && (!has_uv || static_cast<std::size_t>(t.uv[k]) < nuv);
    }
    // finite uvs, as add_mesh and the OBJ loader require: set from Python (Scene.uvs), a NaN or
    // an infinite one made the reference's every lookup NaN (the surface black: each sample
    // dropped) while the kernel read the texel at uv 0
    for (int k = 0; k < 3 && ok && has_uv; ++k) ok = fits_float(s.uvs[t.uv[k]]);
    // normals too (add_mesh and the OBJ loader require finite ones and store them unit
    // length): set from Python (Scene.normals), an infinite one, or one beyond float range,
    // made the kernel's shading normal NaN, the surface black without a non-finite sample
    for (int k = 0; k < 3 && ok && has_n; ++k) ok = fits_float(s.normals[t.n[k]]);
    // some indices given and some not (0, 1, -1), or one below -1: the triangle's normals or
    // uvs were ignored without a word (they are used when all three are given)
    ok = ok && all_or_none(t.n) && all_or_none(t.uv);
    // a finite vertex beyond the geometry range (non-finite ones are dropped by pack_scene)
    int far = -1;
    for (int k = 0; k < 3 && ok; ++k)
      if (finite(s.positions[t.v[k]]) && max_abs(s.positions[t.v[k]]) > limits::kMaxCoordinate)
        far = k;
    if (ok && far < 0) continue;
    const Reporter at(file, primitive_place(s, ShapeType::Triangle, i, "triangles", "triangle"));
    check_index(at.at("material"), t.material, nm, "materials");
    for (int k = 0; k < 3; ++k) check_index(at.at("v").at(k), t.v[k], np, "positions");
    check_all_or_none(at.at("n"), t.n, "normals");
    check_all_or_none(at.at("uv"), t.uv, "uvs");
    for (int k = 0; k < 3 && has_n; ++k) check_index(at.at("n").at(k), t.n[k], nn, "normals");
    for (int k = 0; k < 3 && has_uv; ++k) check_index(at.at("uv").at(k), t.uv[k], nuv, "uvs");
    for (int k = 0; k < 3 && has_uv; ++k)
      for (int c = 0; c < 2; ++c) check_finite(at.at("uv").at(k).at(c), s.uvs[t.uv[k]][c]);
    for (int k = 0; k < 3 && has_n; ++k)
      for (int c = 0; c < 3; ++c) check_finite(at.at("n").at(k).at(c), s.normals[t.n[k]][c]);
    if (far >= 0) check_position(at.at("v").at(far), s.positions[t.v[far]]);
  }
}

glm::dvec3 brightest_texel(const Texture& t) {
  glm::dvec3 b(0.0);
  for (std::size_t k = 0; k + 4 <= t.rgba.size(); k += 4)
    for (int c = 0; c < 3; ++c) b[c] = std::max<double>(b[c], t.rgba[k + c]);
  return b;
}

namespace {

/// Whether a light of Scene::lights can send out any light: a point light's intensity, an
/// environment's radiance, an environment map's scale times its texels, in some channel.
bool light_emits(const Scene& scene, const Light& l) {
  switch (l.type) {
    case LightType::Point:
      return l.intensity.x > 0 || l.intensity.y > 0 || l.intensity.z > 0;
    case LightType::Environment:
      return l.radiance.x > 0 || l.radiance.y > 0 || l.radiance.z > 0;
    case LightType::EnvironmentMap: {
      if (l.texture < 0 || static_cast<size_t>(l.texture) >= scene.textures.size()) return false;
      const Texture& t = scene.textures[static_cast<size_t>(l.texture)];
      for (int c = 0; c < 3; ++c) {
        if (!(l.radiance[c] > 0)) continue;
        for (size_t i = static_cast<size_t>(c); i < t.rgba.size(); i += 4)
          if (t.rgba[i] > 0) return true;
      }
      return false;
    }
    case LightType::Sphere:
    case LightType::Triangle:
      break;
  }
  return true;
}

}  // namespace

std::vector<std::string> light_notes(const Scene& s) {
  if (is_aov(s.integrator.type)) return {};
  auto emissive = [&s](int material) {
    return material >= 0 && static_cast<std::size_t>(material) < s.materials.size() &&
           s.materials[static_cast<std::size_t>(material)].emissive();
  };
  // a shape of an emissive material is an area light, which always emits
  if (std::any_of(s.spheres.begin(), s.spheres.end(),
                  [&](const Sphere& sp) { return emissive(sp.material); }) ||
      std::any_of(s.triangles.begin(), s.triangles.end(),
                  [&](const Triangle& t) { return emissive(t.material); }))
    return {};
  if (s.lights.empty())
    return {in_file(s.path,
                    "the scene has no light (no light entry, no emissive material): the image is "
                    "black")};
  if (std::none_of(s.lights.begin(), s.lights.end(),
                   [&s](const Light& l) { return light_emits(s, l); }))
    return {in_file(s.path,
                    "every light of the scene emits nothing (an intensity, radiance or scale of "
                    "0, or a black environment map): the image is black")};
  return {};
}

std::vector<std::string> point_light_notes(const Scene& s) {
  const IntegratorType t = s.integrator.type;
  if (t != IntegratorType::Whitted && t != IntegratorType::Direct) return {};
  if (!light_notes(s).empty()) return {};  // (no light at all: said there)
  if (std::any_of(s.lights.begin(), s.lights.end(),
                  [&s](const Light& l) { return l.type == LightType::Point && light_emits(s, l); }))
    return {};
  return {in_file(s.path, std::string("integrator ") + type_name(t) +
                              " lights surfaces by point lights alone, and the scene has no "
                              "point light that emits: its emissive shapes and environment show "
                              "only where seen, and its non-specular surfaces are black (path "
                              "lights them)")};
}

std::vector<std::string> radiance_notes(const Scene& s) {
  const double most = std::sqrt(double(FLT_MAX));
  auto largest = [](const glm::dvec3& c) { return std::max({c.x, c.y, c.z}); };
  std::string what;
  double value = 0;
  for (const Material& m : s.materials)
    if ((value = largest(m.emission)) > most) {
      what = "material '" + m.name + "': emission";  // (an MTL material has no JSON place)
      break;
    }
  std::string nearby;  // a point light's: where its samples overflow
  // the box of the geometry, which a point light's irradiance reaches divided by the squared
  // distance: 1e20 at 1000 renders without a dropped sample
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  for (const Sphere& sp : s.spheres)
    if (finite(sp.center) && std::isfinite(sp.radius)) {
      lo = glm::min(lo, sp.center - sp.radius);
      hi = glm::max(hi, sp.center + sp.radius);
    }
  for (const glm::dvec3& p : s.positions)
    if (finite(p)) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
  for (std::size_t i = 0; what.empty() && i < s.lights.size(); ++i) {
    const Light& l = s.lights[i];
    if (l.type == LightType::Environment && (value = largest(l.radiance)) > most)
      what = "/lights/" + std::to_string(i) + "/radiance";
    // a point light's irradiance is intensity / r^2: an intensity of 1e30 rendered black (every
    // lit sample non-finite) without a word, where an emission so bright had this note. Said when
    // geometry may lie within the distance where the squares overflow (the box of the geometry
    // is nearer than it: a bound, never later than the first dropped sample).
    if (l.type == LightType::Point && (value = largest(l.intensity)) > most && lo.x <= hi.x) {
      const double reach = std::sqrt(value / most);
      const glm::dvec3 outside = glm::max(glm::max(lo - l.position, l.position - hi), 0.0);
      if (glm::length(outside) < reach) {
        what = "/lights/" + std::to_string(i) + "/intensity";
        char d[64];
        std::snprintf(d, sizeof d, " within a distance of about %.3g of it", reach);
        nearby = d;
      }
      continue;
    }
    if (l.type != LightType::EnvironmentMap || l.texture < 0 ||
        static_cast<std::size_t>(l.texture) >= s.textures.size())
      continue;
    // a map: its scale times its brightest texel, channel by channel (scales are >= 0)
    value = largest(l.radiance * brightest_texel(s.textures[static_cast<std::size_t>(l.texture)]));
    if (value > most)
      what = "/lights/" + std::to_string(i) + "/scale (times the map's brightest texel)";
  }
  std::vector<std::string> notes;
  if (!what.empty()) {
    char buf[64];
    std::snprintf(buf, sizeof buf, " %.3g is above %.3g", value, most);
    notes.push_back(in_file(s.path, what + buf + ", where a sample's square overflows a float" +
                                        nearby +
                                        ": such samples are dropped as non-finite (lower it and "
                                        "raise film.exposure)"));
  }
  // the other end: a value below the smallest normal float, in which the kernel keeps it (in
  // double precision too), was rounded without a word: a point light of 5e-45 (a scene of size
  // 1e-22) lit 12% too brightly, one of 5e-46 not at all
  auto tiny = [](const glm::dvec3& c) {
    for (int k = 0; k < 3; ++k)
      if (c[k] > 0 && c[k] < double(FLT_MIN)) return c[k];
    return 0.0;
  };
  std::string small;
  double small_value = 0;
  for (const Material& m : s.materials)
    if ((small_value = tiny(m.emission)) > 0) {
      small = "material '" + m.name + "': emission";
      break;
    }
  for (std::size_t i = 0; small.empty() && i < s.lights.size(); ++i) {
    const Light& l = s.lights[i];
    if (l.type == LightType::Point && (small_value = tiny(l.intensity)) > 0)
      small = "/lights/" + std::to_string(i) + "/intensity";
    else if (l.type == LightType::Environment && (small_value = tiny(l.radiance)) > 0)
      small = "/lights/" + std::to_string(i) + "/radiance";
    else if (l.type == LightType::EnvironmentMap && (small_value = tiny(l.radiance)) > 0)
      small = "/lights/" + std::to_string(i) + "/scale";
  }
  if (!small.empty()) {
    char buf[96];
    std::snprintf(buf, sizeof buf, " %.3g is below %.3g, the smallest normal float", small_value,
                  double(FLT_MIN));
    notes.push_back(in_file(s.path, small + buf +
                                        ", in which the kernel keeps it: it is rounded (to 0 "
                                        "below 7e-46), and so is the light it gives (raise it and "
                                        "lower film.exposure)"));
  }
  return notes;
}

std::vector<std::string> energy_gain_notes(const Scene& s) {
  std::vector<std::string> notes;
  if (is_aov(s.integrator.type)) return notes;  // nothing is reflected
  const char* channel[3] = {"red", "green", "blue"};
  std::vector<double> brightest(s.textures.size(), -1.0);  // each texture's largest texel
  for (std::size_t i = 0; i < s.materials.size(); ++i) {
    const Material& m = s.materials[i];
    const std::string name = m.name.empty() ? std::to_string(i) : m.name;
    for (const MaterialParam& param : material_type_def(m.type).params) {
      if ((param.kind != MaterialParam::Colour && param.kind != MaterialParam::ColourOrTexture) ||
          !param.energy)
        continue;
      glm::dvec3 v = m.*param.colour;
      std::string what = param.key;
      const int t = param.kind == MaterialParam::ColourOrTexture ? m.albedo_texture : -1;
      if (t >= 0 && static_cast<std::size_t>(t) < s.textures.size()) {
        // a float texture (PFM, EXR) may hold texels above 1
        if (brightest[t] < 0) {
          const glm::dvec3 b = brightest_texel(s.textures[t]);
          brightest[t] = std::max({b.x, b.y, b.z});
        }
        v = glm::dvec3(brightest[t]);
        what += " texture's brightest texel";
      }
      int c = 0;
      for (int k = 1; k < 3; ++k)
        if (v[k] > v[c]) c = k;
      if (!(v[c] > 1 + 1e-6)) continue;
      notes.push_back(in_file(
          s.path, "material '" + name + "': " + what + " " + format_number(v[c]) +
                      (t >= 0 ? "" : std::string(" in ") + channel[c]) +
                      " is above 1: the surface reflects more light than it receives (each "
                      "bounce gains energy, and Russian roulette does not end such paths)"));
    }
  }
  return notes;
}

}  // namespace lucent::scene_detail
