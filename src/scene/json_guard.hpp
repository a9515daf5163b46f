#pragma once
// What a scene's JSON text must satisfy before it is parsed into a document: a bounded size (a
// pipe or an endless stream is refused after a limit), a bounded nesting depth, and no duplicate
// keys (the JSON parser would silently keep the last one: two materials of the same name, two
// "radius" keys in one sphere).
#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>

namespace lucent::scene_detail {

/// A scene file's largest size (inline triangle lists make big scenes; meshes belong in OBJ).
constexpr std::uint64_t kMaxSceneBytes = 256ull << 20;
/// Deepest nesting of objects and arrays (the format itself needs 7: a transform matrix's row,
/// in its step, in the transform, in a shape, in the shape list, in the scene).
constexpr int kMaxJsonDepth = 64;

/// The text of a scene file: a regular file or a pipe (e.g. /dev/stdin), at most
/// kMaxSceneBytes, no NUL byte. Throws lucent::Error naming the file.
std::string read_scene_text(const std::string& path);

/// A pass over the JSON text that stops at the first object or array nested deeper than
/// kMaxJsonDepth and at the first duplicate key, with "<path>:<line>:<col>: <JSON pointer>: ...",
/// then refuses a text whose document and scene would exceed the host memory lucent allows itself
/// (json_load_bytes), in one line naming the count and the limit. Syntax errors are left to the
/// parser (this pass ignores them).
void check_json_structure(const std::string& text, const std::string& path);

/// What the values of a JSON text take at the peak of a scene's load: the text, its document
/// (nlohmann::json: a 16-byte slot per value, an allocation per array and object, growing arrays
/// twice their size) and the scene's arrays the numbers become. Dense inline meshes peaked at
/// 22-24 times their text (24 MB of "[0,0,0]" positions: 571 MB): counted per value and per
/// container, 1.3-1.5 times that; objects' members (a std::map node each) counted too, 10^6
/// sphere objects (a peak of 870 MB, counted 663 MiB without them) about 1.05 times.
std::uint64_t json_load_bytes(std::uint64_t text_bytes, std::uint64_t values,
                              std::uint64_t containers, std::uint64_t string_bytes,
                              std::uint64_t members);

/// Frees a parsed document from its leaves up, without allocating: nlohmann's destructor moves a
/// container's elements into a stack vector as large as the container first, so destroying a
/// document of a 31-million-element array after the load ran out of memory threw std::bad_alloc
/// inside a noexcept destructor, and the program ended in std::terminate (SIGABRT).
void release_json(nlohmann::json& document);

/// release_json of a document when the scope ends, also when an exception leaves it.
class JsonRelease {
 public:
  explicit JsonRelease(nlohmann::json& document) : document_(document) {}
  ~JsonRelease() { release_json(document_); }
  JsonRelease(const JsonRelease&) = delete;
  JsonRelease& operator=(const JsonRelease&) = delete;

 private:
  nlohmann::json& document_;
};

/// "<line>:<col>" (1-based) of the byte at `offset` in `text`.
std::string line_col_at(const std::string& text, std::size_t offset);

}  // namespace lucent::scene_detail
