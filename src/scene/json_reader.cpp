// The JSON reading helpers (json_reader.hpp).
#include "scene/json_reader.hpp"

#include <cmath>
#include <cstdint>

#include "core/text.hpp"

namespace lucent::scene_detail {

namespace fs = std::filesystem;

std::string json_type_name(const json& j) {
  switch (j.type()) {
    case json::value_t::null:
      return "null";
    case json::value_t::boolean:
      return "a boolean";
    case json::value_t::string:
      return "a string";
    case json::value_t::array:
      return "an array";
    case json::value_t::object:
      return "an object";
    case json::value_t::discarded:
      return "invalid";
    default:
      return "a number";
  }
}

namespace {

/// The value as written, shortened for messages.
std::string show(const json& j) {
  std::string s = j.dump();
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return s;
}

}  // namespace

std::string described(const json& j) {
  return j.is_null() ? json_type_name(j) : json_type_name(j) + " " + show(j);
}

const json& JsonReader::require(const json& obj, const std::string& ptr, const char* key) const {
  auto it = obj.find(key);
  if (it == obj.end()) fail(ptr, std::string("missing required field '") + key + "'");
  return *it;
}

void JsonReader::check_object(const json& j, const std::string& ptr) const {
  if (!j.is_object()) fail(ptr, "must be an object, got " + json_type_name(j));
  // a key is a name or a place in messages, which a NUL would cut short (as in strings)
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string& k = it.key();
    if (k.find('\0') == std::string::npos) continue;
    std::string shown;
    for (char c : k) shown += c ? std::string(1, c) : std::string("\\u0000");
    fail(ptr, "the key '" + shown + "' contains a NUL character (\\u0000)");
  }
}

void JsonReader::check_array(const json& j, const std::string& ptr) const {
  if (!j.is_array()) fail(ptr, "must be an array, got " + json_type_name(j));
}

void JsonReader::check_keys(const json& obj, const std::string& ptr,
                            const std::vector<const char*>& allowed) const {
  check_object(obj, ptr);
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    bool ok = false;
    for (const char* a : allowed) ok = ok || it.key() == a;
    if (!ok) {
      std::string list;
      for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
      fail(ptr + "/" + pointer_key(it.key()), "unknown key (allowed: " + list + ")");
    }
  }
}

double JsonReader::number(const json& j, const std::string& ptr) const {
  if (j.is_string()) {
    // JSON has no NaN/Inf literals; strings are the usual way they sneak in
    const std::string& s = j.get_ref<const std::string&>();
    if (s == "nan" || s == "NaN" || s == "inf" || s == "Infinity" || s == "-inf" ||
        s == "-Infinity")
      fail(ptr, "must be a finite number, got " + s);
  }
  if (!j.is_number()) fail(ptr, "must be a number, got " + described(j));
  return check_finite(at(ptr), j.get<double>());
}

long long JsonReader::integer(const json& j, const std::string& ptr, IntRange range) const {
  // an integer beyond 64 bits, which the parser holds as a float (18446744073709551616): out of
  // range, as 2^63 is (it was "must be an integer, got a number 1.8446744073709552e+19")
  if (j.is_number_float()) {
    const double d = j.get<double>();
    if (std::isfinite(d) && std::floor(d) == d && std::abs(d) >= 9223372036854775808.0)
      fail_range(at(ptr), range, io::shortest_real(d));
  }
  if (!j.is_number_integer() && !j.is_number_unsigned())
    fail(ptr, "must be an integer, got " + described(j));
  // beyond the signed 64-bit range: reported as written, not wrapped around
  if (j.is_number_unsigned() && j.get<std::uint64_t>() > static_cast<std::uint64_t>(range.hi))
    fail_range(at(ptr), range, std::to_string(j.get<std::uint64_t>()));
  long long v = j.get<long long>();
  check_range(at(ptr), v, range);
  return v;
}

bool JsonReader::boolean(const json& j, const std::string& ptr) const {
  if (!j.is_boolean()) fail(ptr, "must be true or false, got " + json_type_name(j));
  return j.get<bool>();
}

std::string JsonReader::string(const json& j, const std::string& ptr) const {
  if (!j.is_string()) fail(ptr, "must be a string, got " + described(j));
  std::string s = j.get<std::string>();
  // "\u0000" is valid JSON, but a path or a name ends there for the C functions that use it
  // ("a.pfm\u0000junk.exr" opened a.pfm), and messages would be cut short
  if (s.find('\0') != std::string::npos)
    fail(ptr, "must not contain a NUL character (\\u0000), at character " +
                  std::to_string(s.find('\0')));
  return s;
}

std::string JsonReader::choice(const json& j, const std::string& ptr,
                               std::initializer_list<const char*> options) const {
  std::string s = string(j, ptr);
  std::string list;
  for (const char* o : options) {
    if (s == o) return s;
    list += std::string(list.empty() ? "" : ", ") + o;
  }
  fail(ptr, "unknown value '" + s + "' (expected one of: " + list + ")");
}

glm::dvec3 JsonReader::vec3(const json& j, const std::string& ptr) const {
  if (!j.is_array() || j.size() != 3)
    fail(ptr, "must be an array of 3 numbers, got " + described(j));
  return {number(j[0], ptr + "/0"), number(j[1], ptr + "/1"), number(j[2], ptr + "/2")};
}

glm::dvec2 JsonReader::vec2(const json& j, const std::string& ptr) const {
  if (!j.is_array() || j.size() != 2) fail(ptr, "must be an array of 2 numbers");
  return {number(j[0], ptr + "/0"), number(j[1], ptr + "/1")};
}

std::string JsonReader::file_path(const json& j, const std::string& ptr) const {
  const std::string s = string(j, ptr);
  if (s.empty()) fail(ptr, "must be a file name, got an empty string");
  return resolve(s);
}

std::string JsonReader::resolve(const std::string& rel) const {
  fs::path p(rel);
  if (p.is_relative()) p = dir_ / p;
  // lexically_normal, except that a ".." after a symbolic link stays: the system resolves
  // "link/.." in the link's target, so a scene reached through a linked directory found
  // "../assets/x.obj" beside the link instead of beside the scene it reads
  fs::path out;
  std::error_code ec;
  for (const fs::path& part : p) {
    if (part.empty() || part == ".") continue;
    if (part == ".." && out.has_relative_path() && out.filename() != ".." &&
        !fs::is_symlink(out, ec)) {
      out = out.parent_path();
      continue;
    }
    if (part == ".." && out == out.root_path() && !out.empty()) continue;  // "/.." is "/"
    out /= part;
  }
  return out.empty() ? "." : out.string();
}

}  // namespace lucent::scene_detail
