// The JSON scene's "lights": point lights and environments (emissive shapes are lights too, made
// from their material). Each entry becomes one SceneBuilder::add_light call.
#include "scene/json_sections.hpp"

namespace lucent::scene_detail {

namespace {

void parse_light(const JsonReader& r, const json& j, const std::string& p, SceneBuilder& b) {
  r.check_object(j, p);
  const std::string name = r.string(r.require(j, p, "type"), p + "/type");
  std::optional<LightType> type = find_type<LightType>(name);
  if (!type)
    r.fail(p + "/type",
           "unknown value '" + name + "' (expected one of: " + scene_light_names() + ")");
  check_light_type(r.at(p + "/type"), *type);  // refuses the emissive shapes' types
  Light l;
  l.type = *type;
  switch (l.type) {
    case LightType::Point:
      r.check_keys(j, p, {"type", "position", "intensity"});
      l.position = r.vec3(r.require(j, p, "position"), p + "/position");
      l.intensity = r.vec3(r.require(j, p, "intensity"), p + "/intensity");
      break;
    case LightType::Environment:
    case LightType::EnvironmentMap:
      // "environment" with "radiance", or with "file" (a map); "environment_map" with "file"
      if (l.type == LightType::EnvironmentMap) {
        r.check_keys(j, p, {"type", "file", "scale"});
        r.require(j, p, "file");
      } else {
        r.check_keys(j, p, {"type", "radiance", "file", "scale"});
      }
      if (j.contains("file")) {
        if (j.contains("radiance"))
          r.fail(p + "/radiance", "give either radiance or file, not both");
        l.type = LightType::EnvironmentMap;
        l.radiance = glm::dvec3(j.contains("scale") ? r.number(j["scale"], p + "/scale") : 1.0);
        std::string file = r.file_path(j["file"], p + "/file");
        try {
          l.texture = b.load_texture(file);
        } catch (const Error& e) {
          r.fail(p + "/file", e.what());
        }
      } else {
        if (j.contains("scale")) r.fail(p + "/scale", "only allowed with file");
        // either key will do: the message names both (it named radiance alone)
        if (!j.contains("radiance"))
          r.fail(p, "missing required field 'radiance' (or 'file', a map)");
        l.radiance = r.vec3(j["radiance"], p + "/radiance");
      }
      break;
    case LightType::Sphere:  // emissive shapes: refused by check_light_type above
    case LightType::Triangle:
      break;
  }
  b.add_light(l);
}

}  // namespace

void parse_lights(const JsonReader& r, const json& j, SceneBuilder& b) {
  r.check_array(j, "/lights");
  for (size_t i = 0; i < j.size(); ++i) parse_light(r, j[i], "/lights/" + std::to_string(i), b);
}

}  // namespace lucent::scene_detail
