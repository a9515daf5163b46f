#pragma once
// Scene -> device buffers: the float, 16-byte aligned layout of kernels/shared/types.h, one
// vector per entry of LC_SCENE_BUFFERS (kernels/shared/registry.h).
#include <string>
#include <vector>

#include "bvh/bvh.hpp"
#include "core/host_blocks.hpp"
#include "lucent/scene.hpp"
#include "render/features.hpp"
#include "shared/types.h"

namespace lucent::render_detail {

/// Rec. 709 luminance of a linear RGB colour: lights' power for their selection probabilities.
inline double luminance(const glm::dvec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

struct PackedScene {
  lc_params params{};
  // host vectors: a large one's storage is a host block, which a CPU device's buffer shares
  // (device_scene.hpp's read_only_buffer): the scene's arrays are held once on such a device
#define LUCENT_PACKED_BUFFER(name, type, ...) sys::HostVector<type> name;
  LC_SCENE_BUFFERS(LUCENT_PACKED_BUFFER)
#undef LUCENT_PACKED_BUFFER
  bvh::BuildStats bvh_stats;
  float bounds_min[3] = {0, 0, 0}, bounds_max[3] = {0, 0, 0};  ///< scene bounds (0 when empty)
  std::size_t skipped_triangles = 0;  ///< degenerate or non-finite, left out with a warning
  /// The powers of the area lights (the first entries of `lights`, emissive shapes in scene
  /// order), kept so that repack_camera can build the light table again for another camera
  /// without packing the shapes again.
  std::vector<double> area_power;
};

/// Sets t.ng_x, ng_y, ng_z to the unit normal of (v1 - v0) x (v2 - v0) of t's float vertices,
/// computed in double and rounded once; returns false, leaving the normal unchanged, where those
/// vertices are collinear.
bool set_triangle_normal(lc_triangle& t);

/// How material `m` maps its albedo texture, in the terms the device reads
/// (docs/rendering-model.md, "Textures"): m's wrap modes and uv scale, its uv offset less whole
/// periods of its wrap mode (repeat 1, mirror 2; the same lookups), in [0, period). A mapping that
/// reads the texels of the default one (repeat, scale 1, a whole offset) is then the default
/// (Material:: default_albedo_mapping()). Without a texture (or one out of range), the default.
Material device_texture_mapping(const Material& m, std::size_t texture_count);

/// Whether the kernel must be built with its texture mapping code (LC_HAS_TEXTURE_MAPPING) for
/// material `m` on spheres (`on_spheres`) or triangles: a wrap mode other than repeat, or a uv
/// scale or offset the kernel applies (spheres'; the host maps triangles' uvs).
bool needs_mapping_code(const Material& m, std::size_t texture_count, bool on_spheres);

/// The camera basis (right, up, forward, with roll applied) as the kernel uses it.
lc_camera pack_camera(const Camera& camera, int width, int height);

/// Whether `scene` renders light-traced caustics: integrator.caustics on the path integrator and
/// a primitive whose material can scatter by a delta lobe (MaterialTypeDef::delta: a mirror,
/// smooth glass, a rough dielectric of ior 1). Without one pack_scene turns caustics off. (The
/// primitives as given: a degenerate one that packing skips counts.)
bool light_traced_caustics(const Scene& scene);

/// Converts and validates the scene, builds the BVH and the light table. With `previous` (an
/// earlier packing) whose geometry (triangle vertices, sphere centres and radii) is the same, its
/// BVH is reused instead of built again; *bvh_reused says which happened.
PackedScene pack_scene(const Scene& scene, const PackedScene* previous = nullptr,
                       bool* bvh_reused = nullptr);

/// In float precision, rays leave a surface offset by its rounding, which scales with the
/// coordinates of its primitive (kernels/util/math.cl, lc_spawn_origin): a warning's text when
/// the largest primitives' offsets exceed 1/16 of the scene's small features (the 10th
/// percentile of primitive sizes: a triangle's longest edge, a sphere's diameter) or when its
/// coordinates reach 100 times the size of its bounds, "" otherwise.
/// A ground triangle of 1e6 under a sphere of 0.01 rendered 16% too dark, a box of size 2 at 1e4
/// leaked light along its inner edges; --precision double renders both right. Also when the
/// scene's bounds are smaller than 1e-10 across: the triangle test's products of three coordinate
/// differences underflow float (a Cornell box at 1e-16 rendered black, at 1e-15 half as bright).
std::string float_rounding_note(const PackedScene& packed);

/// An emitter (a sphere light's radius, a triangle light's square root of area) below 1e-18 of
/// the scene's size: light sampling's density, 1 / its solid angle, overflows float there and
/// its samples give nothing, in either precision (a sphere light of radius 1e-20 rendered black).
/// A warning's text, or "".
std::string tiny_emitter_note(const PackedScene& packed);

/// The notes above that apply to `packed` (pack_scene of `scene`), each "<scene path>: ...":
/// float_rounding_note with float arithmetic, stored_rounding_note, emitter_cut_note,
/// point_light_note and tiny_emitter_note. What a render says once its scene is packed, and `lucent
/// info` with it.
std::vector<std::string> packing_notes(const Scene& scene, const PackedScene& packed,
                                       bool float_arithmetic);

/// The rounding of the scene's coordinates to float, which both precisions store: a warning's
/// text when it moves a surface (a triangle's corner, a sphere's centre and radius) by more than
/// 1/16 of the scene's small features (as float_rounding_note's), "" otherwise. A ground sphere of
/// radius 1e7 whose centre, -9999999.7, was stored as -1e7 left a sphere of radius 0.5 floating
/// 0.3 above it: double rendered that without a word (image-mean z -24 against the reference),
/// after float's warning had recommended double. Coordinates that floats hold exactly (a quad of
/// +-1e6) are not said.
std::string stored_rounding_note(const Scene& scene);

/// What the rounding notes weigh, from the scene's own (double) primitives, those pack_scene
/// keeps: the largest coordinate magnitude of a primitive (a sphere's centre plus its radius),
/// the small features (the 10th percentile of primitive sizes: a triangle's longest edge, a
/// sphere's diameter; 0 without a primitive) and the largest move of a surface by the rounding of
/// its coordinates to float.
struct SceneScale {
  double largest = 0, feature = 0, rounding = 0;
};
SceneScale scene_scale(const Scene& scene);

/// A sphere light cut by another surface (a sphere's or a triangle's) into a thin part: a
/// warning's text when the larger of the two primitives' rounding exceeds 1/16 of that part's
/// depth, "" otherwise. With float arithmetic that rounding is the cutter's spawn offsets and the
/// light's shadow-ray margin (4 point error bounds): smallpt's lamp (radius 600) pokes 0.27
/// through a ceiling sphere of radius 1e5 whose offsets are 0.19, and rendered 2% bright (1.2%
/// once the light's own margin was bounded) without a word. With double arithmetic it is the
/// rounding of the coordinates stored in float (2^-24 of them): walls of radius 1e6 moved the
/// ceiling by 0.025, 9.5% bright. The first emitters only where emitters x primitives pass 2e7.
std::string emitter_cut_note(const PackedScene& packed, bool float_arithmetic);

/// A point light close to a surface against the rounding there: a warning's text when the larger
/// of the light's stored position's rounding (float, 2^-24 of its coordinates) and the nearest
/// surface's (with float arithmetic its spawn offsets, 2^-20 of its coordinates; else its stored
/// floats) exceeds 1/256 of the distance between them, "" otherwise. A light 0.01 above a floor
/// at 1e4 from the origin was lit wrong pixel by pixel in both precisions (65% of the pixels
/// passed against the reference), without a word. The first lights only where lights x
/// primitives pass 2e7.
std::string point_light_note(const PackedScene& packed, bool float_arithmetic);

/// In float precision, an area light (a sphere light or an emissive triangle) within its own size
/// S of another surface whose spawn offsets (2^-20 of its coordinates) exceed 1/256 of S: a
/// warning's text, "" otherwise (and always "" in double). BSDF-sampled rays leave that surface
/// from its offset origin and see the lamp's edges shifted by the offset, so the share of its
/// light MIS gives them keeps a bias of about a tenth to a quarter of offset / S: a square lamp
/// of side 0.006 at 0.003 over a floor of +-60 rendered 0.12% bright, a sphere lamp of radius
/// 0.0078 whose centre is 0.01 above it 0.18% (docs/rendering-model.md, "Precision"). S is a
/// sphere's radius or sqrt of a triangle's area; the distance is from the lamp's vertices and
/// centroid (a sphere's surface) to the nearest non-emitting surface. The first emitters only
/// where emitters x primitives pass 2e7.
std::string area_light_note(const PackedScene& packed, bool float_arithmetic);

/// The radius of the region over which pack_lights reckons an environment light's power: the
/// bounding radius of `packed`'s primitives (1 without any), but no more than `camera`'s distance
/// to what it looks at. The one part of the light table that follows the camera.
double environment_radius(const Camera& camera, const PackedScene& packed);

/// The light table (src/render/lights.cpp): the scene's point and environment lights after the
/// area lights that pack_scene added for emissive shapes (`area_power`: their powers), each light's
/// selection probability and the light_cdf buffer (selection CDF, then each environment map's
/// texel CDF), environment lights weighed over `env_radius` (environment_radius). Sets
/// params.env_light.
void pack_lights(const Scene& scene, PackedScene& packed, std::vector<double> area_power,
                 double env_radius);

/// Appends the light-selection CDF of the probabilities `w` (summing to 1) to `cdf`: the running
/// sums on the kernel's 2^-24 lattice, each light of a positive probability given one lattice step
/// at least (up to 2^24 lights), taken from the largest.
void append_selection_cdf(const std::vector<double>& w, sys::HostVector<float>& cdf);

/// What a packing holds that depends on the camera, for `camera` in place of scene.camera
/// (Renderer::set_camera): everything else of pack_scene(scene) is the same for any camera (the
/// film, whose size sets the aspect ratio and the session's buffers, is the scene's).
struct CameraPacking {
  lc_params params{};  ///< packed.params with the new camera
  /// The light table for the new camera, when it differs from packed's (environment lights
  /// weighed over a new environment_radius); else lights_changed is false and both are empty.
  bool lights_changed = false;
  sys::HostVector<lc_light> lights;
  sys::HostVector<float> light_cdf;
};

/// The camera-dependent part of pack_scene for `camera`, from `packed` = pack_scene(scene) without
/// packing the shapes again: in the bits pack_scene(scene with `camera`) gives. Gives the camera
/// warning pack_scene gives (a pixel finer than float's steps) through scene_detail::warn. The
/// camera must have been validated (scene_detail::validate_camera).
CameraPacking repack_camera(const Scene& scene, const PackedScene& packed, const Camera& camera);

}  // namespace lucent::render_detail
