#pragma once
// The value checks of a scene, written once and used by both ways of making one: the JSON loader
// (src/scene/json_*.cpp) reads a file into the public structs and hands them to SceneBuilder,
// whose add_* / set_* calls run the validators below. Every check names the place of the value as
// a JSON pointer, so a scene built in code and the same scene written in JSON give the same
// message ("scene.json: /materials/glass/ior: must be > 0, got -1").
//
// The JSON loader itself only checks what JSON can get wrong and code cannot: syntax, types,
// unknown keys, missing fields, names of types and materials, integers that do not fit their
// field (it checks those against the same ranges, before narrowing), and the steps of a JSON
// transform.
#include <cstddef>
#include <glm/glm.hpp>
#include <string>

#include "lucent/limits.hpp"
#include "lucent/registry.h"
#include "lucent/scene.hpp"
#include "lucent/scene_builder.hpp"

namespace lucent::scene_detail {

/// `key` as a reference token of a JSON pointer (RFC 6901): '~' written "~0" and '/' "~1", so that
/// a key holding a '/' (a material "wood/oak") is not read as two levels.
std::string pointer_key(const std::string& key);

/// The place of a value: the scene's file (or a built scene's name) and the JSON pointer of the
/// value in it. fail() throws lucent::Error "<file>: <pointer>: <what>" ("<pointer>: <what>" when
/// the scene has no name).
class Reporter {
 public:
  Reporter(std::string file, std::string pointer)
      : file_(std::move(file)), pointer_(std::move(pointer)) {}
  /// The member `key` of this object (escaped: pointer_key), or the element `index` of this array.
  Reporter at(const std::string& key) const { return {file_, pointer_ + "/" + pointer_key(key)}; }
  Reporter at(std::size_t index) const { return at(std::to_string(index)); }
  const std::string& file() const { return file_; }
  const std::string& pointer() const { return pointer_; }
  [[noreturn]] void fail(const std::string& what) const;

 private:
  std::string file_;
  std::string pointer_;
};

/// A number as messages show it (6 significant digits; nan, inf).
std::string format_number(double v);

/// "<file>: <what>", or `what` alone for a scene without a file (built in code).
std::string in_file(const std::string& file, const std::string& what);

// ---------------------------------------------------------------------------------------------
// Checks of one value. Each fails at `at` with a message saying what the value must be and what
// it is; the vector checks name the component (".../albedo/1").

/// An inclusive range of integers.
struct IntRange {
  long long lo, hi;
};
namespace rules {
inline constexpr IntRange kImageSize{1, limits::kMaxImageSize};      ///< film width and height
inline constexpr IntRange kSpp{1, limits::kMaxSpp};                  ///< samples per pixel
inline constexpr IntRange kDepth{1, limits::kMaxDepth};              ///< max_depth, rr_depth
inline constexpr IntRange kSeed{0, limits::kMaxSeed};                ///< the 32-bit seed
inline constexpr IntRange kSplits{0, limits::kMaxDielectricSplits};  ///< dielectric_splits
/// A vertex index of a mesh of n positions.
inline IntRange vertex_index(std::size_t n) { return {0, static_cast<long long>(n) - 1}; }
}  // namespace rules

/// "must be in [lo, hi], got <shown>" (shown: the value as written, which may not fit a long).
[[noreturn]] void fail_range(const Reporter& at, IntRange range, const std::string& shown);
void check_range(const Reporter& at, long long v, IntRange range);
double check_finite(const Reporter& at, double v);
void check_positive(const Reporter& at, double v);                       ///< finite and > 0
void check_non_negative(const Reporter& at, double v);                   ///< finite and >= 0
void check_between(const Reporter& at, double v, double lo, double hi);  ///< finite, in [lo, hi]
void check_point(const Reporter& at, const glm::dvec3& v);               ///< finite components
/// The largest magnitude of v's components (what limits::kMaxCoordinate bounds).
double max_abs(const glm::dvec3& v);
/// v / |v| for any finite v other than 0 (0 stays 0): v is first scaled by the power of two of
/// its largest component, so that the squares of tiny components cannot underflow (the length of
/// [0, 1e-170, 0] was 0: glm::normalize made it NaN, and the checks refused it as zero). The
/// scaling is exact: where glm::normalize has no underflow, the same bits.
glm::dvec3 unit(const glm::dvec3& v);
/// A position in the scene: finite components of magnitude <= limits::kMaxCoordinate.
void check_position(const Reporter& at, const glm::dvec3& v);
/// "<subject> is beyond lucent's geometry range (...)": the message for a coordinate beyond
/// limits::kMaxCoordinate.
std::string beyond_geometry_range(const std::string& what);
void check_colour(const Reporter& at, const glm::dvec3& c);   ///< finite components >= 0
void check_nonzero(const Reporter& at, const glm::dvec3& v);  ///< finite and not (0, 0, 0)
/// A scale given as RGB or as one number (all components equal: the place has no component).
void check_scale(const Reporter& at, const glm::dvec3& s);
/// An affine, invertible 4x4 matrix of finite numbers; entries are named /row/column.
void check_affine(const Reporter& at, const glm::dmat4& m);
/// The determinant of `m` with its columns scaled to unit length: its sign is the orientation,
/// and it is 0 (or near it) only for a singular matrix, whatever its scale.
double unit_determinant(const glm::dmat3& m);
/// The inverse transpose of `m` up to a positive factor: what takes normals (to be made unit
/// length) through `m`.
glm::dmat3 normal_transform(const glm::dmat3& m);
/// A texture index below `textures`, or -1 when `optional`.
void check_texture_index(const Reporter& at, int index, std::size_t textures, bool optional);
/// A light type a scene's "lights" may hold: the emissive shapes' types are refused.
void check_light_type(const Reporter& at, LightType type);
/// The light types a scene's "lights" may hold, "point, environment, ...".
std::string scene_light_names();

// ---------------------------------------------------------------------------------------------
// Validators of one element of a scene, at its place ("/camera", "/materials/<name>",
// "/shapes/<i>", "/lights/<i>", "/textures/<i>").

void validate_camera(const Camera& camera, const Reporter& at);
void validate_film(const Film& film, const Reporter& at);
void validate_integrator(const Integrator& integrator, const Reporter& at);
/// Its size (width and height from 1, 4 floats per texel), then every texel finite and
/// non-negative.
void validate_texture(const Texture& texture, const Reporter& at);
/// How a material maps its albedo texture, at `at` (its "albedo"): wrap modes that exist, uv
/// scales and offsets finite and within limits (lucent/limits.hpp).
void check_texture_mapping(const Material& material, const Reporter& at);
/// The parameters every material has (name, type, emission, albedo texture), then its type's
/// own, by the type's parameter table and its own check (scene/material_type.hpp).
void validate_material(const Material& material, const std::vector<Texture>& textures,
                       const Reporter& at);
void validate_light(const Light& light, std::size_t textures, const Reporter& at);
void validate_sphere(const SphereShape& sphere, const Reporter& at);
void validate_mesh(const MeshShape& mesh, const Reporter& at);

/// A whole Scene, whose fields may have been set directly (the C++ struct, Python's attributes)
/// rather than through SceneBuilder or a JSON file, before it is packed or rendered: the camera,
/// integrator, materials (a nameless one allowed), lights and textures' sizes as the builder
/// checks them, the film from size 1 up (larger than a file's allows: the memory checks bound
/// it), and every index (materials, textures, positions, normals, uvs), so that nothing reads out
/// of range and no NaN camera reaches the kernel. Places name the shape list's entry where
/// `shapes` covers the primitive ("/shapes/3/material", "/shapes/1 (triangle 12)/v/0"), else
/// "/spheres/<i>", "/triangles/<i>". What is rendered safely stays allowed: texel values (a
/// non-finite texel makes the samples that read it non-finite, which are counted), spheres with
/// a NaN centre or radius (never hit), non-finite or degenerate triangles (skipped with a
/// warning when the scene is packed).
void validate_scene(const Scene& scene);

/// A warning's text for every material colour that reflects more than it receives: a component
/// of an albedo (or an albedo texture's texel), a reflectance, a conductor's F0 or a tint above 1
/// (MaterialParam::energy; a diffuse albedo of 2 rendered a white furnace 1.73; diffuse_mirror
/// refuses such values). None for the AOV integrators, which reflect nothing. A session says
/// each once (Renderer::set_scene), the reference each time.
std::vector<std::string> energy_gain_notes(const Scene& scene);

/// A light-transport integrator's black image, said rather than silently rendered: "the scene
/// has no light" (no light entry and no shape of an emissive material), or "every light of the
/// scene emits nothing" (point intensities and environment radiances of 0, environment maps
/// scaled by 0 or black in the channels their scale keeps; no emissive shape). None for the AOV
/// integrators, which need no light. The session (pack_scene) and the reference give them.
std::vector<std::string> light_notes(const Scene& scene);

/// Whitted and direct light surfaces by point lights alone (docs/rendering-model.md): a scene lit
/// otherwise (emissive shapes, an environment) rendered black but for what the camera sees emit,
/// without a word (`scenes/course.json --integrator whitted`: 4074 pixels of 4096 black). A
/// warning for such a scene with either integrator; none where light_notes gives one.
std::vector<std::string> point_light_notes(const Scene& scene);

/// The first emission or environment radiance (or a map's scale times its brightest texel) above
/// sqrt(FLT_MAX), about 1.84e19,
/// as a warning: the kernel and the reference drop a sample whose square overflows a float (the
/// image's variances are floats), so such a light's directly seen pixels rendered black, with a
/// count of non-finite samples and no word of why. (A point light's intensity is not seen
/// directly: it reaches a pixel divided by a squared distance.)
std::vector<std::string> radiance_notes(const Scene& scene);

/// A texture's largest red, green and blue texels (0 for an empty one).
glm::dvec3 brightest_texel(const Texture& texture);

}  // namespace lucent::scene_detail
