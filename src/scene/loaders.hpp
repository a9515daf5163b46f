#pragma once
// Internal scene loading pieces: OBJ/MTL meshes and textures, called by the JSON loader.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <map>
#include <string>
#include <unordered_map>

#include "lucent/scene.hpp"

namespace lucent::scene_detail {

/// Warnings go to the calling thread's ScopedWarningSink if there is one, else to the
/// process-wide hook (stderr by default; tests capture through it).
void warn(const std::string& message);
void set_warning_sink(void (*sink)(const std::string&));

/// While alive, the calling thread's warnings go to `sink` (when it is not null): the sink of a
/// load_scene call or of a render session.
class ScopedWarningSink {
 public:
  explicit ScopedWarningSink(const std::function<void(const std::string&)>& sink);
  ~ScopedWarningSink();
  ScopedWarningSink(const ScopedWarningSink&) = delete;
  ScopedWarningSink& operator=(const ScopedWarningSink&) = delete;

 private:
  const std::function<void(const std::string&)>* previous_;
};

/// The scene materials OBJ meshes made from MTL materials, by "<canonical MTL path>\n<material
/// name>", and their default material (key "obj:default"): a material is shared by the faces of
/// meshes that use the same MTL material (the same OBJ loaded again, two OBJ files naming one
/// library), never with another material of the same name (docs/obj-mtl.md). It also holds the
/// textures loaded from files, by texture_file_key(): SceneBuilder keeps one for its scene.
using ObjMaterials = std::map<std::string, int>;

/// The key of the texture file `path` in an ObjMaterials: its canonical path (where it can be
/// computed) behind a NUL, which no path or material key holds.
std::string texture_file_key(const std::string& path);

/// Loads an OBJ file (and its MTL) into `scene`: positions, normals and UVs are transformed by
/// `transform` (normals by its inverse transpose; a mirroring transform keeps faces' orientation)
/// and appended to the scene's triangle list. When `material_override` >= 0 every face uses it;
/// otherwise MTL materials become scene materials named "<obj file name>:<mtl name>" (made
/// unique when another material has that name), reused through `known` (SceneBuilder's; null:
/// this call's own, which shares the scene's textures by their paths), and faces without one use a
/// default diffuse material. Missing MTL or texture files give a warning naming the file and fall
/// back. Returns the MTL libraries the OBJ names that exist (none with a material override, which
/// reads none): inputs of the scene, as its textures are. `names`: the scene's materials by name
/// (SceneBuilder's), to which the new materials are added; null: made from the scene's list when
/// a new material needs a free name. Throws lucent::Error naming the file (and line) of a parse
/// error.
std::vector<std::string> load_obj(Scene& scene, const std::string& path,
                                  const glm::dmat4& transform, int material_override,
                                  ObjMaterials* known = nullptr,
                                  std::unordered_map<std::string, int>* names = nullptr);

/// Loads an image (PNG, JPG, BMP, TGA: 8-bit decoded from sRGB to linear; HDR, PFM, EXR kept
/// linear) as a scene texture, reusing an already loaded one with the same canonical path: the
/// one `known` (SceneBuilder's) names, and records it there; without `known`, any of the scene's
/// textures whose path is the file. Returns its index. Throws lucent::Error naming the file when
/// it cannot be read.
int load_texture(Scene& scene, const std::string& path, ObjMaterials* known = nullptr);

/// Decodes a texture file's bytes (`path` names it in messages): what load_texture does after
/// reading the file. Throws lucent::Error naming `path`.
Texture decode_texture(const unsigned char* data, std::size_t size, const std::string& path);

/// `texels` texels of 8-bit sRGB data, `channels` (1 to 4: grey, grey + alpha, RGB, RGBA) bytes
/// each, to linear RGBA floats (alpha kept linear) at `rgba`.
void decode_srgb8(const std::uint8_t* data, std::size_t texels, int channels, float* rgba);

/// The files a command's outputs must not overwrite because `scene` (loaded from `scene_path`)
/// reads them: the scene file, then its textures and environment maps (those of MTL materials
/// too), its OBJ meshes and their MTL libraries.
std::vector<std::string> scene_inputs(const std::string& scene_path, const Scene& scene);

}  // namespace lucent::scene_detail
