#pragma once
// Scenes built in code, without JSON. SceneBuilder is the one way into a Scene that checks it:
// the JSON loader (load_scene, parse_scene) reads a file into the structs below and makes the
// same calls, so a scene built in code gets exactly the checks and the messages of a JSON scene.
// An error names the element as a JSON pointer would, prefixed with the builder's name:
//
//   lucent::SceneBuilder b("my tool");
//   lucent::Material glass;
//   glass.name = "glass";
//   glass.type = lucent::MaterialType::Dielectric;
//   glass.ior = -1;
//   b.add_material(glass);   // throws lucent::Error "my tool: /materials/glass/ior: must be > 0,
//   got -1"
//
// Places: set_camera "/camera", set_film "/film", set_integrator "/integrator", add_material
// "/materials/<name>", the n-th add_sphere / add_mesh / add_obj "/shapes/<n>", the n-th add_light
// "/lights/<n>", the n-th add_texture "/textures/<n>" (0-based, in call order). Warnings (add_obj's
// missing MTL file or texture, ...) go to the calling thread's ScopedWarningSink
// (lucent/warnings.hpp), else to stderr.
#include <cstdint>
#include <glm/glm.hpp>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

#include "lucent/scene.hpp"

namespace lucent {

/// A sphere (the JSON shape "sphere").
struct SphereShape {
  glm::dvec3 center{0, 0, 0};
  double radius = 1;     ///< > 0
  std::string material;  ///< the name of a material added before
};

/// A triangle mesh given in memory (the JSON shape "triangles").
struct MeshShape {
  std::vector<glm::dvec3> positions;  ///< at least one
  /// Three per triangle, indices into positions. A triangle's front side, the one an emissive
  /// material emits from, is the side of (v1 - v0) x (v2 - v0).
  std::vector<int> indices;
  std::vector<glm::dvec3> normals;  ///< per-vertex shading normals: empty, or one per position
  std::vector<glm::dvec2> uvs;      ///< texture coordinates: empty, or one per position
  /// Object to world, affine and invertible (normals go through its inverse transpose; a
  /// mirroring transform keeps each face's front side).
  glm::dmat4 transform{1.0};
  std::string material;  ///< the name of a material added before
};

/// An OBJ file (the JSON shape "mesh"; docs/obj-mtl.md).
struct ObjShape {
  std::string file;  ///< as given (relative to the working directory)
  glm::dmat4 transform{1.0};
  std::string material;  ///< a material for every face; empty: the file's MTL materials
};

/// A texture from linear RGBA floats, 4 per texel, rows from the top of the image. `name` is
/// what `lucent info` shows for it (may be empty).
Texture texture_from_rgba(int width, int height, std::vector<float> rgba, std::string name = "");

/// A texture from 8-bit sRGB-encoded data (as a PNG stores it), `channels` (1: grey, 2: grey and
/// alpha, 3: RGB, 4: RGBA) per texel, rows from the top: colours are decoded from sRGB to linear
/// as image files are, alpha is kept linear. Throws lucent::Error when `data` does not hold
/// width x height x channels bytes.
Texture texture_from_srgb8(int width, int height, int channels,
                           const std::vector<std::uint8_t>& data, std::string name = "");

/// A material of `type` with the scene format's defaults for the type's parameters (a
/// conductor's specular 0.9, a diffuse_mirror's reflectance 0.2: README, "materials"), no
/// emission. A default-constructed Material keeps the struct's defaults whatever its type.
Material material_of_type(MaterialType type, std::string name = "");

/// A point light: `intensity` in W/sr.
Light point_light(const glm::dvec3& position, const glm::dvec3& intensity);
/// A constant environment of `radiance`.
Light environment_light(const glm::dvec3& radiance);
/// An equirectangular environment map: a texture index (SceneBuilder::add_texture or
/// load_texture), its texels multiplied by `scale`.
Light environment_map(int texture, double scale = 1);

class SceneBuilder {
 public:
  /// `name` starts every error message, as a scene file's path does ("" for none); it becomes
  /// Scene::path.
  explicit SceneBuilder(std::string name = "");

  /// Each set_ / add_ call checks what it is given and throws lucent::Error naming the place of
  /// the first wrong value; the builder is unchanged then.
  void set_camera(const Camera& camera);  ///< focus_distance 0: the distance to look_at
  void set_film(const Film& film);        ///< default_filter_radius() gives a filter's default
  void set_integrator(const Integrator& integrator);

  /// A texture held in memory (texture_from_rgba, texture_from_srgb8); returns its index for
  /// Material::albedo_texture and environment_map().
  int add_texture(Texture texture);
  /// An image file (PNG, JPG, HDR, PFM, EXR, ...), loaded once per file; returns its index.
  int load_texture(const std::string& file);
  /// A material, known from then on by its name (non-empty, unique). Returns its index.
  int add_material(const Material& material);

  void add_sphere(const SphereShape& sphere);
  void add_mesh(const MeshShape& mesh);
  void add_obj(const ObjShape& obj);
  /// A point light, an environment or an environment map; at most one environment of either
  /// kind. Sphere and triangle lights are made from shapes with an emissive material.
  void add_light(const Light& light);

  /// The scene so far.
  const Scene& scene() const { return scene_; }
  /// The finished scene; the builder is left empty.
  Scene build();

 private:
  int material_index(const std::string& name, const std::string& pointer) const;
  std::string shape_place() const;
  Scene scene_;
  /// The materials OBJ meshes made from MTL materials, by MTL library and material name, and the
  /// textures loaded from files, by canonical path (scene_detail::ObjMaterials), for the meshes
  /// and materials after them to share.
  std::map<std::string, int> obj_materials_;
  /// The scene's materials by name, for add_material's and the shapes' lookups (a search of the
  /// list for each made a scene of N materials load in N^2 / 2 comparisons: 200,000 took 99.6 s).
  std::unordered_map<std::string, int> material_names_;
};

}  // namespace lucent
