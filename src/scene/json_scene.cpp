// JSON scenes: the entry points (load_scene, parse_scene) and syntax errors. The sections are
// read by json_settings.cpp, json_materials.cpp, json_shapes.cpp and json_lights.cpp into the
// public structs, and built and checked by SceneBuilder, as a scene built in code is. Every
// problem is reported as "<file>: <JSON pointer>: <what is wrong>" (or "<file>:<line>:<col>: ..."
// for syntax errors).
#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/host_memory.hpp"
#include "lucent/error.hpp"
#include "lucent/scene.hpp"
#include "scene/json_guard.hpp"
#include "scene/json_sections.hpp"
#include "scene/loaders.hpp"

namespace lucent {

using scene_detail::json;
namespace fs = std::filesystem;

namespace {

/// Finds where a parse stops for a reason json::parse reports without a place (a number literal
/// out of double range, such as 1e999): a SAX pass that only records the error's byte count.
struct ErrorLocator : nlohmann::json_sax<json> {
  size_t byte = 0;
  bool null() override { return true; }
  bool boolean(bool) override { return true; }
  bool number_integer(number_integer_t) override { return true; }
  bool number_unsigned(number_unsigned_t) override { return true; }
  bool number_float(number_float_t, const string_t&) override { return true; }
  bool string(string_t&) override { return true; }
  bool binary(binary_t&) override { return true; }
  bool start_object(std::size_t) override { return true; }
  bool key(string_t&) override { return true; }
  bool end_object() override { return true; }
  bool start_array(std::size_t) override { return true; }
  bool end_array() override { return true; }
  bool parse_error(std::size_t position, const std::string&,
                   const nlohmann::detail::exception&) override {
    byte = position;
    return false;
  }
};

/// Builds a JSON document into `root` in place, so that release_json frees it, also the part built
/// when an exception leaves (json::parse builds into a local of its own, whose destructor frees
/// it by allocating). nlohmann's own builder, detail::json_sax_dom_parser, is not public: its
/// template parameters changed in 3.12. A syntax error or a number out of range is thrown as the
/// parser's own exception (json::parse_error, json::out_of_range), as json::parse throws it.
class DocumentBuilder : public nlohmann::json_sax<json> {
 public:
  explicit DocumentBuilder(json& root) : root_(root) {}
  bool null() override { return put(nullptr); }
  bool boolean(bool v) override { return put(v); }
  bool number_integer(number_integer_t v) override { return put(v); }
  bool number_unsigned(number_unsigned_t v) override { return put(v); }
  bool number_float(number_float_t v, const string_t&) override { return put(v); }
  bool string(string_t& v) override { return put(std::move(v)); }
  bool binary(binary_t& v) override { return put(json::binary(std::move(v))); }
  bool start_object(std::size_t) override {
    stack_.push_back(place(json::object()));
    return true;
  }
  bool start_array(std::size_t) override {
    stack_.push_back(place(json::array()));
    return true;
  }
  bool end_object() override { return pop(); }
  bool end_array() override { return pop(); }
  bool key(string_t& k) override {
    // (check_json_structure refused duplicate keys)
    member_ = &stack_.back()->get_ref<json::object_t&>()[k];
    return true;
  }
  bool parse_error(std::size_t, const std::string& token,
                   const nlohmann::detail::exception& e) override {
    if (const auto* p = dynamic_cast<const json::parse_error*>(&e)) throw *p;
    if (const auto* o = dynamic_cast<const json::out_of_range*>(&e)) throw *o;
    error_ = std::string(e.what()) + " (at '" + token + "')";
    return false;
  }
  /// The error of a parse that returned false without an exception of the parser's types.
  const std::string& error() const { return error_; }

 private:
  /// The new value's place: the root, the end of the array being read, or the member whose key
  /// came last.
  json* place(json&& v) {
    if (stack_.empty()) {
      root_ = std::move(v);
      return &root_;
    }
    json& parent = *stack_.back();
    if (parent.is_array()) {
      json::array_t& a = parent.get_ref<json::array_t&>();
      a.push_back(std::move(v));
      return &a.back();
    }
    *member_ = std::move(v);
    return member_;
  }
  bool put(json&& v) {
    place(std::move(v));
    return true;
  }
  bool pop() {
    stack_.pop_back();
    return true;
  }

  json& root_;
  std::vector<json*> stack_;  ///< the open objects and arrays (at most kMaxJsonDepth)
  json* member_ = nullptr;
  std::string error_ = "invalid JSON";
};

/// The scene in `root`: its sections in a fixed order (materials before the shapes naming them).
/// Relative file names are taken from `dir`.
Scene build_scene(const json& root, const std::string& path, const fs::path& dir) {
  using namespace scene_detail;
  JsonReader r(path, dir);
  SceneBuilder b(path);
  r.check_keys(root, "", {"camera", "film", "integrator", "materials", "shapes", "lights"});
  if (root.contains("camera")) parse_camera(r, root["camera"], b);
  if (root.contains("film")) parse_film(r, root["film"], b);
  if (root.contains("integrator")) parse_integrator(r, root["integrator"], b);
  if (root.contains("materials")) parse_materials(r, root["materials"], b);
  if (root.contains("shapes")) parse_shapes(r, root["shapes"], b);
  if (root.contains("lights")) parse_lights(r, root["lights"], b);
  return b.build();
}

/// parse_scene, with the relative file names taken from `dir`.
Scene parse_scene_in(const std::string& text, const std::string& path, const fs::path& dir) {
  scene_detail::check_json_structure(text, path);  // nesting depth, duplicate keys, memory
  // the document is built in place and freed by release_json, also when an exception leaves
  json root;
  const scene_detail::JsonRelease release(root);
  try {
    DocumentBuilder builder(root);
    if (!json::sax_parse(text, &builder)) throw Error(path + ": invalid JSON: " + builder.error());
  } catch (const json::parse_error& e) {
    std::string what = e.what();
    auto pos = what.find("syntax error");
    if (pos != std::string::npos) what = what.substr(pos);
    // e.byte counts the bytes read, 1-based: the place is the byte before it
    throw Error(path + ":" + scene_detail::line_col_at(text, e.byte > 0 ? e.byte - 1 : 0) +
                ": invalid JSON: " + what);
  } catch (const json::exception& e) {
    // out_of_range 406, "number overflow parsing '1e999'", comes without a place: a SAX pass
    // finds where the parser stopped, just after the literal, and we step back to its start.
    ErrorLocator locator;
    json::sax_parse(text, &locator);
    size_t i = std::min(locator.byte, text.size());
    while (i > 0 && std::strchr("0123456789+-.eE", text[i - 1]) && text[i - 1] != '\0') --i;
    std::string literal = text.substr(i, std::min(locator.byte, text.size()) - i);
    throw Error(path + ":" + scene_detail::line_col_at(text, i) + ": " +
                (e.id == 406 && !literal.empty()
                     ? "number out of range (not a finite double): " + literal
                     : std::string(e.what())));
  }
  return build_scene(root, path, dir);
}

}  // namespace

Scene parse_scene(const std::string& text, const std::string& path) {
  // as load_scene reads a file (the parser stopped at a NUL and took what came before it)
  if (const size_t at = text.find('\0'); at != std::string::npos)
    throw Error(path + ": byte " + std::to_string(at + 1) +
                " is a NUL byte: not a text scene file");
  return parse_scene_in(text, path, fs::path(path).parent_path());
}

namespace {

/// Where a scene file's relative file names start: its directory. A scene read from a pipe
/// (/dev/stdin, <(command), a FIFO) has none, so the current directory, as for a shell; they were
/// looked for in /dev or /dev/fd. /dev/stdin redirected from a file (`< scene.json`) is that
/// file, so its directory.
fs::path scene_dir(const std::string& path) {
  std::error_code ec;
  const fs::path dir = fs::path(path).parent_path();
  const bool fd_alias = dir == "/dev" || dir == "/dev/fd" ||
                        (dir.filename() == "fd" && dir.parent_path().parent_path() == "/proc");
  if (fd_alias) {
    // a file descriptor's link names its file; a pipe's ("pipe:[1234]") is no path
    const fs::path target = fs::canonical(path, ec);
    return !ec && fs::is_regular_file(target, ec) ? target.parent_path() : fs::path();
  }
  return fs::is_regular_file(path, ec) ? dir : fs::path();
}

}  // namespace

Scene load_scene(const std::string& path) {
  Scene scene;
  {
    const std::string text = scene_detail::read_scene_text(path);  // bounded; pipes allowed
    scene = parse_scene_in(text, path, scene_dir(path));
  }
  sys::return_free_memory();  // the text and the loaders' arrays, freed in many pieces
  return scene;
}

namespace scene_detail {

std::vector<std::string> scene_inputs(const std::string& scene_path, const Scene& scene) {
  std::vector<std::string> inputs{scene_path};
  for (const Texture& t : scene.textures)
    if (!t.path.empty()) inputs.push_back(t.path);
  for (const ShapeEntry& e : scene.shapes) {
    if (!e.file.empty()) inputs.push_back(e.file);
    inputs.insert(inputs.end(), e.libraries.begin(), e.libraries.end());
  }
  return inputs;
}

}  // namespace scene_detail

}  // namespace lucent
