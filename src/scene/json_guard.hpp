#pragma once
// What a scene's JSON text must satisfy before it is parsed into a document: a bounded size (a
// pipe or an endless stream is refused after a limit), a bounded nesting depth, and no duplicate
// keys (the JSON parser would silently keep the last one: two materials of the same name, two
// "radius" keys in one sphere).
#include <cstdint>
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
/// kMaxJsonDepth and at the first duplicate key, with "<path>:<line>:<col>: <JSON pointer>: ...".
/// Syntax errors are left to the parser (this pass ignores them).
void check_json_structure(const std::string& text, const std::string& path);

/// "<line>:<col>" (1-based) of the byte at `offset` in `text`.
std::string line_col_at(const std::string& text, std::size_t offset);

}  // namespace lucent::scene_detail
