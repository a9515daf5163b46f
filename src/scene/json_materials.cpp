// The JSON scene's "materials": a map from name to material. parse_material() reads one
// material's type and parameters; SceneBuilder::add_material checks them (scene/validate.hpp).
#include "scene/json_sections.hpp"

namespace lucent::scene_detail {

void parse_materials(const JsonReader& r, const json& j, SceneBuilder& b) {
  r.check_object(j, "/materials");
  for (auto it = j.begin(); it != j.end(); ++it)
    b.add_material(parse_material(r, it.value(), "/materials/" + it.key(), it.key(), b));
}

Material parse_material(const JsonReader& r, const json& j, const std::string& p,
                        const std::string& name, SceneBuilder& b) {
  r.check_object(j, p);
  Material m;
  m.name = name;
  m.type = r.type<MaterialType>(r.require(j, p, "type"), p + "/type");
  switch (m.type) {
    case MaterialType::Diffuse:
      r.check_keys(j, p, {"type", "albedo", "emission"});
      break;
    case MaterialType::Mirror:
      r.check_keys(j, p, {"type", "reflectance", "emission"});
      m.specular = glm::dvec3(1.0);
      if (j.contains("reflectance")) m.specular = r.vec3(j["reflectance"], p + "/reflectance");
      break;
    case MaterialType::Dielectric:
      r.check_keys(j, p, {"type", "ior", "tint", "emission"});
      m.specular = glm::dvec3(1.0);
      if (j.contains("tint")) m.specular = r.vec3(j["tint"], p + "/tint");
      break;
    case MaterialType::Conductor:
      r.check_keys(j, p, {"type", "specular", "roughness", "emission"});
      m.specular = glm::dvec3(0.9);
      if (j.contains("specular")) m.specular = r.vec3(j["specular"], p + "/specular");
      break;
    case MaterialType::Plastic:
      r.check_keys(j, p, {"type", "albedo", "specular", "roughness", "ior", "emission"});
      m.specular = glm::dvec3(1.0);
      if (j.contains("specular")) m.specular = r.vec3(j["specular"], p + "/specular");
      break;
  }
  if (j.contains("albedo")) {
    const json& a = j["albedo"];
    if (a.is_object()) {
      r.check_keys(a, p + "/albedo", {"texture"});
      std::string file = r.string(r.require(a, p + "/albedo", "texture"), p + "/albedo/texture");
      try {
        m.albedo = glm::dvec3(1.0);
        m.albedo_texture = b.load_texture(r.resolve(file));
      } catch (const Error& e) {
        r.fail(p + "/albedo/texture", e.what());
      }
    } else {
      m.albedo = r.vec3(a, p + "/albedo");
    }
  }
  if (j.contains("ior")) m.ior = r.number(j["ior"], p + "/ior");
  if (j.contains("roughness")) m.roughness = r.number(j["roughness"], p + "/roughness");
  if (j.contains("emission")) m.emission = r.vec3(j["emission"], p + "/emission");
  return m;
}

}  // namespace lucent::scene_detail
