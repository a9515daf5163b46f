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

namespace {

TextureWrap wrap_mode(const JsonReader& r, const json& j, const std::string& p) {
  const std::string w = r.choice(j, p, {"repeat", "clamp", "mirror"});
  return w == "repeat" ? TextureWrap::Repeat
                       : (w == "clamp" ? TextureWrap::Clamp : TextureWrap::Mirror);
}

/// A texture reference's mapping: "wrap" (one mode, or [u, v]), "uv_scale" and "uv_offset"
/// ([u, v]), into m's albedo mapping; their values are checked by SceneBuilder::add_material
/// (check_texture_mapping), at the same places.
void parse_texture_mapping(const JsonReader& r, const json& v, const std::string& p, Material& m) {
  if (v.contains("wrap")) {
    const json& w = v["wrap"];
    if (w.is_array()) {
      if (w.size() != 2)
        r.fail(p + "/wrap",
               "must be a wrap mode or [u, v] of two, got an array of " + std::to_string(w.size()));
      m.albedo_wrap_u = wrap_mode(r, w[0], p + "/wrap/0");
      m.albedo_wrap_v = wrap_mode(r, w[1], p + "/wrap/1");
    } else {
      if (!w.is_string())
        r.fail(p + "/wrap", "must be a wrap mode or [u, v] of two, got " + described(w));
      m.albedo_wrap_u = m.albedo_wrap_v = wrap_mode(r, w, p + "/wrap");
    }
  }
  if (v.contains("uv_scale")) m.albedo_uv_scale = r.vec2(v["uv_scale"], p + "/uv_scale");
  if (v.contains("uv_offset")) m.albedo_uv_offset = r.vec2(v["uv_offset"], p + "/uv_offset");
}

}  // namespace

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
      r.check_keys(v, pp, {"texture", "wrap", "uv_scale", "uv_offset"});
      std::string file = r.file_path(r.require(v, pp, "texture"), pp + "/texture");
      parse_texture_mapping(r, v, pp, m);
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
