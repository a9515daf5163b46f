#pragma once
// Reading a JSON scene: the helpers every section reader uses (json_settings.cpp,
// json_materials.cpp, json_shapes.cpp, json_lights.cpp, and the material types' parameter
// readers). They check what JSON can get wrong (syntax aside): types, unknown keys, missing
// fields, type names, integers that do not fit their field. Values are checked afterwards, once
// for JSON and built scenes, by SceneBuilder (scene/validate.hpp). Every failure throws
// lucent::Error "<file>: <JSON pointer>: <what>".
#include <filesystem>
#include <glm/glm.hpp>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "lucent/types.hpp"
#include "scene/validate.hpp"

namespace lucent::scene_detail {

using nlohmann::json;

class JsonReader {
 public:
  /// `file` names the scene in messages; relative paths in it are taken from `dir`.
  JsonReader(std::string file, std::filesystem::path dir)
      : file_(std::move(file)), dir_(std::move(dir)) {}

  const std::string& file() const { return file_; }
  /// The place `ptr` of this file, for the checks of scene/validate.hpp.
  Reporter at(const std::string& ptr) const { return Reporter(file_, ptr); }
  [[noreturn]] void fail(const std::string& ptr, const std::string& what) const {
    at(ptr).fail(what);
  }

  /// obj[key], failing with "missing required field 'key'" at `ptr` (the object's place).
  const json& require(const json& obj, const std::string& ptr, const char* key) const;
  void check_object(const json& j, const std::string& ptr) const;
  void check_array(const json& j, const std::string& ptr) const;
  /// An object whose keys are all in `allowed`.
  void check_keys(const json& obj, const std::string& ptr,
                  const std::vector<const char*>& allowed) const;

  /// A finite number (JSON has no NaN or Inf; the strings "nan", "inf", ... are named as such).
  double number(const json& j, const std::string& ptr) const;
  /// An integer in `range` (checked before it is narrowed to its field, with the field's range).
  long long integer(const json& j, const std::string& ptr, IntRange range) const;
  bool boolean(const json& j, const std::string& ptr) const;
  std::string string(const json& j, const std::string& ptr) const;
  /// One of `options` (enumerations that are not registries: transfer, tonemap).
  std::string choice(const json& j, const std::string& ptr,
                     std::initializer_list<const char*> options) const;
  /// A registry type by its name (lucent/types.hpp).
  template <class E>
  E type(const json& j, const std::string& ptr) const {
    std::string s = string(j, ptr);
    if (std::optional<E> v = find_type<E>(s)) return *v;
    fail(ptr, "unknown value '" + s + "' (expected one of: " + type_names<E>() + ")");
  }
  /// [x, y, z] and [u, v] of numbers.
  glm::dvec3 vec3(const json& j, const std::string& ptr) const;
  glm::dvec2 vec2(const json& j, const std::string& ptr) const;

  /// A path of the scene file, relative to its directory unless absolute.
  std::string resolve(const std::string& rel) const;
  /// A file name: a non-empty string (resolve("") named the scene's directory, "." in messages
  /// such as ".: is a directory, not a texture"), resolved.
  std::string file_path(const json& j, const std::string& ptr) const;

 private:
  std::string file_;
  std::filesystem::path dir_;
};

/// "a string", "an array", ... for messages.
std::string json_type_name(const json& j);
/// "a number 1.5", "a string \"x\"", ...: the type and the value (null is both: not "null null"),
/// for "got ..." in messages.
std::string described(const json& j);

}  // namespace lucent::scene_detail
