#pragma once
// The scene description shared by the kernel renderer and the reference integrator. Everything is
// in double precision and world space; the renderer converts to the device's float layout.
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "lucent/warnings.hpp"
// the registry's type lists alone: its kernel helper macros (LC_ENABLED, LC_PARAMS,
// LC_SCENE_BUFFERS, ...) were defined in every file of a program that included lucent's headers
#define LUCENT_REGISTRY_TYPES_ONLY
#include "lucent/registry.h"
#undef LUCENT_REGISTRY_TYPES_ONLY

namespace lucent {

// The structs below hold GLM's vectors and matrices, whose layout follows the GLM macros of the
// program that includes this header: lucent is built with GLM's defaults, and a program that
// makes them aligned (GLM_FORCE_DEFAULT_ALIGNED_GENTYPES with GLM_FORCE_INTRINSICS: a dvec3 of
// 32 bytes) passed scenes the library misread (a camera's up read as zero) without a word.
static_assert(sizeof(glm::dvec2) == 2 * sizeof(double) &&
                  sizeof(glm::dvec3) == 3 * sizeof(double) &&
                  sizeof(glm::dmat4) == 16 * sizeof(double) &&
                  alignof(glm::dvec3) == alignof(double),
              "lucent's structs need GLM's default layout: build without "
              "GLM_FORCE_DEFAULT_ALIGNED_GENTYPES (and other GLM macros that change the size or "
              "alignment of its types)");

// The type enums are generated from the registries (lucent/registry.h, kernels/shared/registry.h
// in the source tree): one enumerator per entry, with the entry's value.
#define LUCENT_REGISTRY_ENUMERATOR(ID, Name, value, ...) Name = value,

struct Camera {
  glm::dvec3 position{0, 0, 5};
  glm::dvec3 look_at{0, 0, 0};
  glm::dvec3 up{0, 1, 0};
  double fov_degrees = 45;    ///< vertical field of view
  double roll_degrees = 0;    ///< rotation about the viewing direction
  double aperture = 0;        ///< thin-lens aperture radius (0: pinhole)
  double focus_distance = 0;  ///< distance to the plane in focus (0: distance to look_at)
};

enum class FilterType { LC_FILTER_TYPES(LUCENT_REGISTRY_ENUMERATOR) };
enum class Transfer { Srgb, Gamma, Linear };
enum class ToneMap { Clamp, Reinhard, Aces };

/// The scene format's names of the display settings ("srgb", "reinhard", ...).
inline const char* transfer_name(Transfer t) {
  return t == Transfer::Srgb ? "srgb" : t == Transfer::Gamma ? "gamma" : "linear";
}
inline const char* tonemap_name(ToneMap t) {
  return t == ToneMap::Clamp ? "clamp" : t == ToneMap::Reinhard ? "reinhard" : "aces";
}

struct Filter {
  FilterType type = FilterType::Box;
  double radius = 0.5;  ///< in pixels
};

struct Film {
  int width = 512;
  int height = 512;
  Filter filter;
  Transfer transfer = Transfer::Srgb;
  double gamma = 2.2;   ///< used when transfer is Gamma
  double exposure = 0;  ///< in stops, applied to 8-bit outputs
  ToneMap tonemap = ToneMap::Clamp;
};

/// Integrators, then the AOVs (first-hit outputs), in one enum.
enum class IntegratorType {
  LC_INTEGRATOR_TYPES(LUCENT_REGISTRY_ENUMERATOR) LC_AOV_TYPES(LUCENT_REGISTRY_ENUMERATOR)
};

/// The random numbers of the camera samples (kernels/shared/rng.h): Owen-scrambled Sobol, or
/// independent numbers (what per-pixel z-tests such as lucent compare assume).
enum class SamplerType { LC_SAMPLER_TYPES(LUCENT_REGISTRY_ENUMERATOR) };

struct Integrator {
  IntegratorType type = IntegratorType::Path;
  int max_depth = 8;
  int rr_depth = 4;  ///< Russian roulette from this depth
  int spp = 16;
  std::uint32_t seed = 0;
  double ao_distance = 0;  ///< ambient occlusion ray length; 0: unbounded
  bool mis = true;         ///< path: combine light and BSDF sampling (false: light sampling only)
  SamplerType sampler = SamplerType::Sobol;
  /// path: the largest component a contribution after a scattering may have; larger ones are
  /// scaled down to it (docs/rendering-model.md, "Clamping"). 0: off. Biased when it binds.
  double clamp = 0;
  /// path: caustic paths (light, one or more delta scatterings, one non-delta vertex seen by the
  /// camera) come from light tracing instead of the camera path (docs/rendering-model.md,
  /// "Caustics by light tracing"). Pinhole and thin-lens cameras.
  bool caustics = false;
  /// path: at the first N smooth-dielectric vertices of a camera path (glass: a delta reflection
  /// with probability F, a delta refraction with 1 - F) both lobes are followed, each weighted
  /// by its probability, instead of one chosen at random (docs/rendering-model.md, "Integrators").
  /// 0: off. The same expected image; less noise where the camera sees light through glass, at
  /// up to 2^N branches per camera sample.
  int dielectric_splits = 2;
};

enum class MaterialType { LC_MATERIAL_TYPES(LUCENT_REGISTRY_ENUMERATOR) };

/// How a texture coordinate outside [0, 1] reads the image (docs/rendering-model.md,
/// "Textures"): repeat (the image tiles), clamp (clamp to edge: the border texels extend) or
/// mirror (tiles, every other one mirrored). The values are the kernel's LC_WRAP_*.
enum class TextureWrap { Repeat, Clamp, Mirror };

/// The scene format's names of the wrap modes ("repeat", "clamp", "mirror").
inline const char* texture_wrap_name(TextureWrap w) {
  return w == TextureWrap::Repeat ? "repeat" : w == TextureWrap::Clamp ? "clamp" : "mirror";
}

struct Material {
  std::string name;
  MaterialType type = MaterialType::Diffuse;
  glm::dvec3 albedo{0.8, 0.8, 0.8};
  int albedo_texture = -1;  ///< index into Scene::textures, -1 for none
  /// How the albedo texture covers the surface: it is read at uv' = uv * albedo_uv_scale +
  /// albedo_uv_offset, wrapped in u and v by albedo_wrap_u and albedo_wrap_v (the defaults read
  /// the image once per uv unit, repeating). Unused without a texture.
  TextureWrap albedo_wrap_u = TextureWrap::Repeat;
  TextureWrap albedo_wrap_v = TextureWrap::Repeat;
  glm::dvec2 albedo_uv_scale{1, 1};
  glm::dvec2 albedo_uv_offset{0, 0};
  glm::dvec3 emission{0, 0, 0};
  glm::dvec3 specular{1, 1, 1};  ///< mirror reflectance / glass tint / glossy F0 colour
  double ior = 1.5;
  double roughness = 0.1;  ///< GGX alpha
  bool emissive() const { return emission.x > 0 || emission.y > 0 || emission.z > 0; }
  /// The albedo texture is read as by default: repeating, uv as given.
  bool default_albedo_mapping() const {
    return albedo_wrap_u == TextureWrap::Repeat && albedo_wrap_v == TextureWrap::Repeat &&
           albedo_uv_scale == glm::dvec2(1, 1) && albedo_uv_offset == glm::dvec2(0, 0);
  }
};

struct Sphere {
  glm::dvec3 center{0, 0, 0};
  double radius = 1;
  int material = 0;
};

/// One triangle of the scene's single, world-space triangle list.
struct Triangle {
  int v[3] = {0, 0, 0};      ///< indices into Scene::positions
  int n[3] = {-1, -1, -1};   ///< indices into Scene::normals, all three -1 when absent
  int uv[3] = {-1, -1, -1};  ///< indices into Scene::uvs, all three -1 when absent
  int material = 0;
};

/// Light types. A scene's `lights` hold Point, Environment and EnvironmentMap; Sphere and Triangle
/// lights are the emissive shapes (materials with emission), made when the scene is packed.
enum class LightType { LC_LIGHT_TYPES(LUCENT_REGISTRY_ENUMERATOR) };

/// Explicit lights. Emissive shapes are area lights without an entry here.
struct Light {
  LightType type = LightType::Point;
  glm::dvec3 position{0, 0, 0};
  glm::dvec3 intensity{0, 0, 0};  ///< point: W/sr
  glm::dvec3 radiance{0, 0, 0};   ///< environment radiance, or the scale of a map
  int texture = -1;               ///< environment map
};

/// Shape types: spheres, and triangles (inline triangle lists and OBJ meshes alike).
enum class ShapeType { LC_SHAPE_TYPES(LUCENT_REGISTRY_ENUMERATOR) };
#undef LUCENT_REGISTRY_ENUMERATOR  // (it stayed defined in every program that included this)

/// One entry of the scene's shape list, in the order given (the JSON "shapes" array, or
/// SceneBuilder's add_sphere / add_mesh / add_obj calls): the primitives it made. Error messages
/// name a shape by its index in this list ("/shapes/3/radius").
struct ShapeEntry {
  ShapeType type = ShapeType::Sphere;
  std::string file;       ///< the OBJ file of a mesh; empty for a sphere or an inline triangle list
  std::size_t first = 0;  ///< first sphere (Scene::spheres) or triangle (Scene::triangles)
  std::size_t count = 0;  ///< number of spheres or triangles
  /// The MTL libraries a mesh's OBJ file named that exist (read, or refused as unreadable): the
  /// scene reads them, so outputs must not overwrite them (scene_inputs)
  std::vector<std::string> libraries;
};

struct Texture {
  std::string path;
  int width = 0;
  int height = 0;
  std::vector<float> rgba;  ///< linear RGBA, row 0 at the top of the image
};

struct Scene {
  std::string path;  ///< the file the scene came from, for messages
  Camera camera;
  Film film;
  Integrator integrator;
  std::vector<Material> materials;
  std::vector<Sphere> spheres;
  std::vector<glm::dvec3> positions;
  std::vector<glm::dvec3> normals;
  std::vector<glm::dvec2> uvs;
  std::vector<Triangle> triangles;
  std::vector<Light> lights;
  std::vector<Texture> textures;
  std::vector<ShapeEntry> shapes;  ///< the shape list as given, for messages and statistics

  /// Index of the material named `name`, or -1.
  int find_material(const std::string& name) const;
};

/// Loads a JSON scene (format: README.md, "Scene format"). Throws lucent::Error naming the file
/// and the JSON path of the first problem (`scene.json: /shapes/3/radius: must be > 0, got -1`).
/// Its warnings (a focus_distance without an aperture, an OBJ's missing MTL file, ...) go to the
/// calling thread's ScopedWarningSink (lucent/warnings.hpp), else to stderr; parse_scene's too.
Scene load_scene(const std::string& path);

/// Parses a JSON scene held in memory; `path` is used for messages and relative file names.
Scene parse_scene(const std::string& json_text, const std::string& path);

}  // namespace lucent
