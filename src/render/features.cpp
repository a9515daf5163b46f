#include "render/features.hpp"

#include <algorithm>

#include "cl/pocl.hpp"
#include "lucent/error.hpp"
#include "render/pack.hpp"
#include "scene/material_type.hpp"

namespace lucent::render_detail {

const std::vector<std::string>& all_features() {
  static const std::vector<std::string> all = [] {
    std::vector<std::string> f;
    auto add = [&f](const char* name) {
      if (std::find(f.begin(), f.end(), name) == f.end()) f.push_back(name);
    };
#define LUCENT_TYPE_FEATURE(ID, Name, value, name, feature, ...) add(#feature);
#define LUCENT_OTHER_FEATURE(feature, what) add(#feature);
    LC_SHAPE_TYPES(LUCENT_TYPE_FEATURE)
    LC_OTHER_FEATURES(LUCENT_OTHER_FEATURE)
    LC_MATERIAL_TYPES(LUCENT_TYPE_FEATURE)
    LC_LIGHT_TYPES(LUCENT_TYPE_FEATURE)
    LC_FILTER_TYPES(LUCENT_TYPE_FEATURE)
    LC_SAMPLER_TYPES(LUCENT_TYPE_FEATURE)
    LC_INTEGRATOR_TYPES(LUCENT_TYPE_FEATURE)
    LC_AOV_TYPES(LUCENT_TYPE_FEATURE)
#undef LUCENT_TYPE_FEATURE
#undef LUCENT_OTHER_FEATURE
    return f;
  }();
  return all;
}

namespace {

/// The one camera feature: the thin-lens code (LC_OTHER_FEATURES' lens). Every camera field that
/// scene_features reads goes through here, and so through camera_features_differ.
bool camera_has_lens(const Camera& c) { return c.aperture > 0; }

}  // namespace

bool camera_features_differ(const Camera& a, const Camera& b) {
  return camera_has_lens(a) != camera_has_lens(b);
}

std::vector<std::string> scene_features(const Scene& scene, const PackedScene& packed) {
  // which type of each list the scene uses, by enum value
  bool shape[LC_SHAPE_COUNT] = {}, material[LC_MAT_COUNT] = {}, light[LC_LIGHT_COUNT] = {};
  bool filter[LC_FILTER_COUNT] = {}, integrator[LC_INTEGRATOR_COUNT] = {};
  bool sampler[LC_SAMPLER_COUNT] = {};
  shape[LC_SHAPE_SPHERE] = !packed.spheres.empty();
  shape[LC_SHAPE_TRIANGLE] = !packed.triangles.empty();
  // materials some primitive uses (a declared but unused material costs nothing)
  std::vector<char> used(scene.materials.size(), 0), on_spheres(scene.materials.size(), 0);
  for (const lc_sphere& sp : packed.spheres) used[sp.material] = on_spheres[sp.material] = 1;
  for (const lc_triangle& t : packed.triangles) used[t.material] = 1;
  bool textured = false, mapped = false;
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    if (!used[i]) continue;
    const Material& m = scene.materials[i];
    material[static_cast<int>(m.type)] = true;
    textured = textured || m.albedo_texture >= 0;
    // a texture read otherwise than repeating, or a sphere's uvs scaled or offset (the host maps
    // triangles' uvs; a mapping equivalent to the default is the default)
    mapped = mapped || needs_mapping_code(m, scene.textures.size(), on_spheres[i]);
  }
  for (const lc_light& l : packed.lights) light[l.type] = true;
  filter[static_cast<int>(scene.film.filter.type)] = true;
  integrator[static_cast<int>(scene.integrator.type)] = true;
  sampler[static_cast<int>(scene.integrator.sampler)] = true;
  bool smooth = false, uvs = false;
  for (const lc_triangle& t : packed.triangles) {
    smooth = smooth || (t.flags & LC_TRI_HAS_NORMALS);
    uvs = uvs || (t.flags & LC_TRI_HAS_UVS);
  }
  const bool clamped = scene.integrator.clamp > 0 && scene.integrator.type == IntegratorType::Path;
  const bool caustics = (packed.params.flags & LC_FLAG_CAUSTICS) != 0;  // pack_scene decides
  // a used BSDF that chooses between delta lobes (MaterialTypeDef::splits: smooth glass) on a
  // path-traced scene
  bool split_lobes = false;
  for (size_t i = 0; i < scene.materials.size(); ++i)
    split_lobes =
        split_lobes || (used[i] && scene_detail::material_type_def(scene.materials[i].type).splits);
  const bool splitting = packed.params.splits > 0 && split_lobes;
  const bool other[] = {smooth,  uvs && textured, textured, mapped, camera_has_lens(scene.camera),
                        clamped, caustics,        splitting};
#define LUCENT_COUNT(feature, what) +1
  static_assert(sizeof(other) / sizeof(other[0]) == 0 LC_OTHER_FEATURES(LUCENT_COUNT),
                "one condition per LC_OTHER_FEATURES entry, in its order");
#undef LUCENT_COUNT

  // in the order of all_features()
  std::vector<std::string> f;
  auto add = [&f](bool on, const char* name) {
    if (on && std::find(f.begin(), f.end(), name) == f.end()) f.push_back(name);
  };
  int k = 0;
#define LUCENT_USED(list, ID, value, feature) add(list[value], #feature);
#define LUCENT_SHAPE(ID, Name, value, name, feature, ...) LUCENT_USED(shape, ID, value, feature)
#define LUCENT_OTHER(feature, what) add(other[k++], #feature);
#define LUCENT_MAT(ID, Name, value, name, feature, ...) LUCENT_USED(material, ID, value, feature)
#define LUCENT_LIGHT(ID, Name, value, name, feature, ...) LUCENT_USED(light, ID, value, feature)
#define LUCENT_FILTER(ID, Name, value, name, feature, ...) LUCENT_USED(filter, ID, value, feature)
#define LUCENT_SAMPLER(ID, Name, value, name, feature, ...) LUCENT_USED(sampler, ID, value, feature)
#define LUCENT_INT(ID, Name, value, name, feature, ...) LUCENT_USED(integrator, ID, value, feature)
  LC_SHAPE_TYPES(LUCENT_SHAPE)
  LC_OTHER_FEATURES(LUCENT_OTHER)
  LC_MATERIAL_TYPES(LUCENT_MAT)
  LC_LIGHT_TYPES(LUCENT_LIGHT)
  LC_FILTER_TYPES(LUCENT_FILTER)
  LC_SAMPLER_TYPES(LUCENT_SAMPLER)
  LC_INTEGRATOR_TYPES(LUCENT_INT)
  LC_AOV_TYPES(LUCENT_INT)
#undef LUCENT_USED
#undef LUCENT_SHAPE
#undef LUCENT_OTHER
#undef LUCENT_MAT
#undef LUCENT_LIGHT
#undef LUCENT_FILTER
#undef LUCENT_SAMPLER
#undef LUCENT_INT
  return f;
}

std::string feature_defines(const Scene& scene, const PackedScene& packed, bool specialize) {
  std::string d;
  for (const std::string& f : specialize ? scene_features(scene, packed) : all_features())
    d += " -D " + f;
  return d;
}

std::string build_options(const Scene& scene, const PackedScene& packed,
                          const RenderOptions& options) {
  std::string o = "-cl-std=CL1.2" + feature_defines(scene, packed, options.specialize);
  if (options.precision == Precision::Double) o += " -D LC_DOUBLE";
  if (options.fast_math) o += " -cl-fast-relaxed-math";
  return o;
}

std::string device_defines(const DeviceInfo& device) {
  std::string d = device.type == "CPU" && cl_util::is_pocl(device) ? " -D LC_DEVICE_POCL_CPU" : "";
  if (device.fp64) d += " -D LC_ACCUM_DOUBLE";  // a pass's sums in double (megakernel.cl)
  // the light sums in double: a double CAS add (integrator/caustics.cl)
  if (light_sums_double(device)) d += " -D LC_LIGHT_DOUBLE";
  return d;
}

bool light_sums_double(const DeviceInfo& device) { return device.fp64 && device.int64_atomics; }

void check_precision_support(const DeviceInfo& device, Precision precision) {
  if (precision == Precision::Double && !device.fp64)
    // (the library's message: Python and C++ callers have no --precision option)
    throw Error("double precision: device '" + device.name +
                "' has no double-precision floating point (cl_khr_fp64); render in float "
                "precision (--precision float) or on another device (--device)");
}

}  // namespace lucent::render_detail
