// The JSON scene's "materials": a map from name to material. parse_material() reads one
// material's type and parameters; SceneBuilder::add_material checks them (scene/validate.hpp).
#include <vector>

#include "scene/json_sections.hpp"
#include "scene/material_type.hpp"

namespace lucent::scene_detail {

void parse_materials(const JsonReader& r, const json& j, SceneBuilder& b) {
  r.check_object(j, "/materials");
  for (auto it = j.begin(); it != j.end(); ++it)
    b.add_material(
        parse_material(r, it.value(), "/materials/" + pointer_key(it.key()), it.key(), b));
}

Material parse_material(const JsonReader& r, const json& j, const std::string& p,
                        const std::string& name, SceneBuilder& b) {
  r.check_object(j, p);
  Material m = material_of_type(r.type<MaterialType>(r.require(j, p, "type"), p + "/type"), name);
  const MaterialTypeDef& def = material_type_def(m.type);
  std::vector<const char*> keys = {"type", "emission"};
  for (const MaterialParam& param : def.params) keys.push_back(param.key);
  r.check_keys(j, p, keys);
  for (const MaterialParam& param : def.params) {
    const std::string pp = p + "/" + param.key;
    if (!j.contains(param.key)) continue;
    const json& v = j[param.key];
    if (param.kind == MaterialParam::ColourOrTexture && v.is_object()) {
      r.check_keys(v, pp, {"texture"});
      std::string file = r.file_path(r.require(v, pp, "texture"), pp + "/texture");
      try {
        m.*param.colour = glm::dvec3(1.0);
        m.albedo_texture = b.load_texture(file);
      } catch (const Error& e) {
        r.fail(pp + "/texture", e.what());
      }
    } else if (param.colour) {
      m.*param.colour = r.vec3(v, pp);
    } else {
      m.*param.number = r.number(v, pp);
    }
  }
  if (j.contains("emission")) m.emission = r.vec3(j["emission"], p + "/emission");
  return m;
}

}  // namespace lucent::scene_detail
