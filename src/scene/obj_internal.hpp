#pragma once
// Pieces of the OBJ/MTL loader (scene/obj.cpp assembles triangles): the checks of the files'
// text (obj_check.cpp) and the MTL libraries and their mapping to lucent materials
// (obj_mtl.cpp).
#include <tiny_obj_loader.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

#include "lucent/scene.hpp"
#include "scene/loaders.hpp"

namespace lucent::scene_detail::obj {

/// Largest OBJ file read (tinyobjloader holds the text and its arrays at once).
constexpr std::uint64_t kMaxObjBytes = 1ull << 30;
/// Largest MTL file read.
constexpr std::uint64_t kMaxMtlBytes = 64ull << 20;
/// Most triangles one OBJ file may produce (67 million: several GiB of scene and BVH).
constexpr std::uint64_t kMaxTriangles = 1ull << 26;
/// Most corners of one polygon: tinyobjloader stores a face's corner count in an unsigned char
/// (mesh_t::num_face_vertices), so a polygon of 256 to 1024 corners came back with its count
/// wrapped (300 as 44) and was refused as "inconsistent face list", without a line.
constexpr int kMaxFaceVertices = 255;

/// The text is served to tinyobjloader a window at a time, and each window given back (to the
/// system) once read (obj.cpp), where the system allows it (Linux: madvise); elsewhere the text
/// stays whole until tinyobjloader is done.
constexpr std::uint64_t kTextWindow = 1ull << 20;
#if defined(__linux__)
constexpr bool kTextGivenBack = true;
#else
constexpr bool kTextGivenBack = false;
#endif

/// The host memory tinyobjloader's arrays take while it reads vertices, normals, texture
/// coordinates, elements (f, l and p statements) and their corners: an upper bound of what it
/// was measured to hold at once (peak resident memory, tinyobjloader 2.0.0rc10: a 400,000-
/// triangle soup 88 MB against 101 here, a 200x200 grid of triangles 76 against 85, of quads 47
/// against 56, of quads with normals and texture coordinates 51 against 62). A vertex or normal
/// is 12 bytes of floats in an array that doubles as it grows; an element is an entry of 32
/// bytes in its list and an array of its corners of its own (48 bytes for three, about 24 a
/// corner more for a polygon); a corner is 12 bytes of indices, doubled as they grow, and copied
/// once more when its shape is done.
inline std::uint64_t tinyobj_bytes(std::int64_t vertices, std::int64_t normals,
                                   std::int64_t texcoords, std::int64_t elements,
                                   std::int64_t corners) {
  return std::uint64_t(16 * (vertices + normals) + 12 * texcoords + 96 * elements + 36 * corners +
                       24 * std::max<std::int64_t>(corners - 3 * elements, 0));
}

/// What the check of an OBJ file's text counted.
struct TextCounts {
  std::int64_t vertices = 0, normals = 0, texcoords = 0, triangles = 0;
  /// f, l and p statements, and their corners
  std::int64_t elements = 0, corners = 0;
  /// The most that tinyobjloader's arrays (tinyobj_bytes) and the text not yet given back
  /// (kTextWindow) hold at once while it reads the text: the text read so far and the arrays
  /// made of it, at each line.
  std::uint64_t reading_bytes = 0;
  /// The names of the `mtllib` statements, in order, each once (split at spaces and tabs, `\ `
  /// escaping one; a word starting with '#' ends the list; the whole rest of the line when that
  /// is a library and a name split from it is not)
  std::vector<std::string> libraries;
  /// A `usemtl` comes before the first `mtllib`.
  bool usemtl_before_mtllib = false;
  /// An f, l or p element ends with a comment ("f 1 2 3 # top"): tinyobjloader would read the
  /// '#' as an index (see blank_element_comments).
  bool element_comments = false;
  /// The names of the usemtl statements that tinyobjloader does not read whole, each once, in
  /// order: a name is the rest of the line, trimmed ("usemtl my mat", "usemtl red # note"), where
  /// tinyobjloader reads the first word. The text it reads names them by alias (alias_usemtl).
  std::vector<std::string> usemtl_names;
  /// The first line whose statement the OBJ format does not have, and the statement (0: none).
  long foreign_line = 0;
  std::string foreign_statement;
  long foreign_lines = 0;  ///< lines of statements OBJ does not have (ignored, with a warning)
};

/// The host memory that loading an OBJ file holds at once (obj.cpp, load_obj), in order, never
/// all together: the text (twice while a copy names materials by alias); the text not yet read
/// and tinyobjloader's arrays (TextCounts::reading_bytes); tinyobjloader's arrays as it leaves
/// them and the scene's arrays grown to take the mesh (the old blocks and the new ones). `held`:
/// the scene's arrays before; `grown`: after; `need`: the most at once, those held included.
struct MeshLoadBytes {
  std::uint64_t held = 0, grown = 0, need = 0;
};
MeshLoadBytes mesh_load_bytes(const Scene& scene, std::uint64_t text_bytes, const TextCounts& c);

/// The name that stands for usemtl_names[k] in the OBJ text tinyobjloader reads: one word, which
/// starts with a control character no material name has (a usemtl naming such a word is aliased
/// too).
std::string usemtl_alias(std::size_t k);

/// `text` with each usemtl statement naming one of `names` (TextCounts::usemtl_names) made
/// "usemtl <usemtl_alias(k)>" (the lines kept).
std::string alias_usemtl(const std::string& text, const std::vector<std::string>& names);

/// A file an OBJ or MTL file names (an `mtllib` library, a map's texture): `name` relative to `dir`
/// (the naming file's directory), its backslashes read as slashes when the name as given does not
/// exist (a Windows path).
std::filesystem::path named_file(const std::filesystem::path& dir, const std::string& name);

/// Checks an OBJ file's text before tinyobjloader sees it: every number of a v, vn and vt line
/// (present, a number, finite, within float range), every index of an f, l and p element (an
/// integer, not 0, within the vertices, texture coordinates and normals the file defines, the
/// negative ones relative to those defined so far), polygons of at most kMaxFaceVertices corners
/// and at most kMaxTriangles triangles, no such line continued with a backslash, and a file of no
/// vertex or face with a statement OBJ does not have (a PLY, STL or glTF file); notes the MTL
/// libraries. Throws lucent::Error("<path>:<line>: ...").
TextCounts check_obj_text(const std::string& path, const std::string& text);

/// Turns the comments at the end of `text`'s f, l and p lines ("f 1 2 3 # top") into spaces, in
/// place (the lines and their offsets kept): tinyobjloader reads every word of such a line as an
/// index, and refused the '#' as a malformed face.
void blank_element_comments(std::string& text);

/// Checks the numbers of an MTL file's statements that carry them (Ka, Kd, Ks, Ke, Tf, Ns, Ni,
/// d, Tr, illum, ...): finite, within float range, colours not negative. Throws
/// lucent::Error("<path>:<line>: ...").
void check_mtl_text(const std::string& path, const std::string& text);

/// The MTL text tinyobjloader reads: `text` with the options of its texture statements (map_Kd,
/// bump, ...: `-o u [v [w]]`, `-clamp on`, ...) removed: lucent reads map_Kd's -s, -o and -clamp
/// itself (mtl_material_names) and no others. Each option takes the arguments that fit it, up to
/// its count (tinyobjloader takes three numbers after -o, -s and -t, and `map_Kd -o 0.5 tex.png`
/// lost its file name); the last word of a statement is always (part of) the file name. The lines
/// are kept. `ignored`, if given, receives each option of a map_Kd statement that lucent does not
/// read and that would change the texture's look had it read it (`-t` other than 0, `-mm` other
/// than 0 1, `-cc on`, `-colorspace` other than sRGB), with its arguments, and its line.
struct IgnoredOption {
  long line = 0;
  std::string option;  ///< "-s 4 4"
};
std::string strip_texture_options(const std::string& text,
                                  std::vector<IgnoredOption>* ignored = nullptr);

/// A `newmtl` statement of an MTL file: the material's name (the rest of the line, trimmed: a '#'
/// is part of it, as tinyobjloader, Blender and assimp read it) and its line, and what of its
/// statements lucent needs beyond tinyobjloader's material_t.
struct MtlName {
  std::string name;
  long line = 0;
  /// its last map_Kd statement's line (0 when it has none) and the options of it that lucent
  /// reads: `-s u [v [w]]` (uv scale; v 1 when not given), `-o u [v [w]]` (uv offset; v 0), w
  /// ignored; `-clamp on` (clamp to edge in u and v; `-clamp` alone is on, as `-clamp off` is
  /// off)
  long kd_line = 0;
  glm::dvec2 kd_scale{1, 1};
  glm::dvec2 kd_offset{0, 0};
  bool kd_clamp = false;
  /// its last Tf (or Kt) statement's line, 0 when it has none, and its tag (for messages);
  /// `tf_numbers`: that statement gives numbers (not the `spectral` form, which tinyobjloader
  /// misreads; the `xyz` form is put in numbers first, read_colour_forms)
  long tf_line = 0;
  std::string tf_tag;
  bool tf_numbers = false;
};
std::vector<MtlName> mtl_material_names(const std::string& text);

/// `text` (an MTL file's, checked by check_mtl_text) with the colour statements that
/// tinyobjloader would read as zeros put in numbers, line for line: `xyz x [y z]` (CIE XYZ) as
/// linear sRGB (D65; one number is x = y = z), negative channels taken as 0 with a warning (but
/// for Ka, which is not read); `Ka`/`Kd`/`Ks`/`Ke spectral file [factor]` made 0 0 0, with a
/// warning (for Kd, Ks, Ke). `Tf` and `Kt spectral` stay (MaterialMapper warns of them on a
/// transparent material). A colour of one number is grey (`Kd 0.5` is `Kd 0.5 0.5 0.5`).
std::string read_colour_forms(const std::string& path, const std::string& text,
                              std::vector<std::string>* warnings);

/// `s` without the spaces and tabs at its ends.
std::string trim(const std::string& s);

/// "a, b, c, d and 3 more", for messages: the first `shown` of `n` items, `item(i)` writing each.
template <class Item>
std::string first_items(std::size_t n, std::size_t shown, const Item& item) {
  std::string list;
  for (std::size_t i = 0; i < n && i < shown; ++i) list += (i ? ", " : "") + item(i);
  if (n > shown) list += " and " + std::to_string(n - shown) + " more";
  return list;
}

/// Removes the UTF-8 byte-order marks (EF BB BF, which Notepad and other Windows tools write)
/// at the start of `text`, and blanks those at the start of a line (files joined with `cat`):
/// tinyobjloader read one as part of its statement, which vanished without a word (a vertex lost
/// and every later index shifted by one; an mtllib or newmtl not read).
inline void strip_utf8_bom(std::string& text) {
  static const char kBom[] = "\xEF\xBB\xBF";
  std::size_t lead = 0;
  while (text.compare(lead, 3, kBom) == 0) lead += 3;
  text.erase(0, lead);
  for (std::size_t at = text.find(kBom); at != std::string::npos; at = text.find(kBom, at + 3))
    if (at > 0 && text[at - 1] == '\n') text.replace(at, 3, "   ");  // (the lines kept)
}

/// Line (1-based) of the `n`-th (0-based) statement `tag` of `text`, or 0.
long line_of_statement(const std::string& text, const char* tag, std::int64_t n);

/// `text` (tinyobjloader's messages) with each "line N" and "line: N" made "line N-by".
std::string shift_line_numbers(const std::string& text, long by);

/// Turns tinyobjloader's error text into one lucent::Error naming the file and line.
[[noreturn]] void throw_parse_error(const std::string& path, const std::string& err);

/// The non-empty lines of `text`, trimmed (tinyobjloader's warnings and errors).
std::vector<std::string> lines_of(const std::string& text);

/// Reads the libraries named by `mtllib` (relative to the OBJ's directory), all of them at
/// tinyobjloader's first call, with a bound, checks their text, and remembers which file each
/// material came from, since texture paths are relative to it. Missing or unreadable libraries
/// are recorded (the caller warns); a malformed one is recorded as `error` (the caller throws).
/// A material name defined again is a warning. When disabled (a material override) nothing is
/// read.
class MtlReader : public tinyobj::MaterialReader {
 public:
  /// `names`: the OBJ's libraries (TextCounts::libraries); `usemtl_names`: the names its text
  /// gives by alias (TextCounts::usemtl_names), added to the material map when read.
  MtlReader(std::filesystem::path dir, std::vector<std::string> names, bool enabled,
            std::vector<std::string> usemtl_names = {})
      : dir_(std::move(dir)),
        names_(std::move(names)),
        usemtl_names_(std::move(usemtl_names)),
        enabled_(enabled) {}

  bool operator()(const std::string& name, std::vector<tinyobj::material_t>* materials,
                  std::map<std::string, int>* map, std::string* warn, std::string* err) override;

  std::vector<std::string> libraries;   ///< libraries that exist (read or unreadable)
  std::vector<std::string> missing;     ///< libraries that do not exist
  std::vector<std::string> unreadable;  ///< libraries that exist but cannot be read (messages)
  std::vector<std::string> origin;      ///< the library of each material, by index
  std::vector<MtlName> definition;      ///< each material's newmtl statement and more, by index
  std::vector<std::string> warnings;    ///< the libraries' own warnings, prefixed with their path
  std::string error;                    ///< the first malformed library's error

 private:
  /// Reads one library; false when it is malformed.
  bool read(const std::string& path, std::vector<tinyobj::material_t>* materials,
            std::map<std::string, int>* map);

  /// Adds the aliases of usemtl_names_ to `map` (each name whole, else before its comment).
  void add_aliases(std::map<std::string, int>* map) const;

  std::filesystem::path dir_;
  std::vector<std::string> names_;
  std::vector<std::string> usemtl_names_;
  bool enabled_;
  bool done_ = false;
  /// each material name's first definition: library and line
  std::map<std::string, std::pair<std::string, long>> defined_;
};

/// Creates scene materials from MTL materials on first use (docs/obj-mtl.md).
class MaterialMapper {
 public:
  MaterialMapper(Scene& scene, ObjMaterials& known, std::unordered_map<std::string, int>* names,
                 const std::string& obj_path, const std::vector<tinyobj::material_t>& mats,
                 const std::vector<std::string>& origin, const std::vector<MtlName>& definition);

  /// The scene material of MTL material `id` (created on first use), or the default one.
  int get(int id);
  int default_material();

 private:
  int convert(const tinyobj::material_t& t, const std::string& mtl_path, const MtlName& def);
  /// Throws lucent::Error "<mtl>:<line>: material '<name>': ior (Ni): must be ..." when the
  /// material converted from MTL material `def` fails the scene's checks (validate_material).
  void check_converted(const Material& m, const std::string& mtl_path, const MtlName& def) const;
  /// `name` when no material has it, else with the OBJ file's parent directories in front
  /// ("b/model.obj:paint"), else with "#2", "#3", ... after it.
  std::string free_name(const std::string& name, bool with_path);
  /// The scene's materials by name: load_obj's `names`, or made from the list when first needed.
  std::unordered_map<std::string, int>& names();
  /// Adds material `m` to the scene and its name to names(); returns its index.
  int add(const Material& m);

  Scene& scene_;
  ObjMaterials& known_;
  std::filesystem::path obj_path_;  ///< canonical
  const std::vector<tinyobj::material_t>& mats_;
  const std::vector<std::string>& origin_;
  const std::vector<MtlName>& definition_;
  std::vector<int> index_;
  int default_ = -1;
  std::set<std::string> warned_;
  /// free_name's lookups (a search of the list for each new name made an MTL library of N
  /// materials take N^2 / 2 comparisons: 80,000 of them loaded in 9.4 s; a set made from the
  /// whole list by each OBJ load made K meshes of a scene of N materials take K N)
  std::unordered_map<std::string, int>* names_;
  std::unordered_map<std::string, int> own_names_;
  bool own_made_ = false;
};

}  // namespace lucent::scene_detail::obj
