// OBJ meshes through tinyobjloader: the file read with a bound and its text checked first
// (obj_check.cpp), polygons triangulated here (concave ones included) and appended to the scene's
// world-space triangle list, MTL materials mapped by obj_mtl.cpp (docs/obj-mtl.md).
#include <tiny_obj_loader.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <set>
#include <sstream>
#include <streambuf>

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

#include "core/file_io.hpp"
#include "core/host_memory.hpp"
#include "lucent/error.hpp"
#include "scene/loaders.hpp"
#include "scene/obj_internal.hpp"
#include "scene/validate.hpp"

namespace lucent::scene_detail {

namespace fs = std::filesystem;
using obj::lines_of;

namespace {

// Serves `head`, then `body`, to tinyobjloader without copying them, a window at a time, and
// gives the whole pages of `body` it has read back to the system as it goes (Linux:
// madvise(MADV_DONTNEED) makes them zeros, like writing zeros to them, which the owner of a
// string may do): the text need not be held whole beside tinyobjloader's arrays, which grow as
// the text is read (a 10^6-triangle soup: 98 MiB of text and about 200 MiB of arrays). `body`
// is spent: what was read of it is zeros.
class SpentText : public std::streambuf {
 public:
  SpentText(const std::string& head, std::string& body) : body_(body) {
    char* h = const_cast<char*>(head.data());
    setg(h, h, h + head.size());
  }

 protected:
  int_type underflow() override {
    if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
    if (next_ >= body_.size()) return traits_type::eof();
    release(next_);  // tinyobjloader reads forward only (it never puts a character back)
    char* b = &body_[0] + next_;
    const std::size_t n = std::min(std::size_t(obj::kTextWindow), body_.size() - next_);
    setg(b, b, b + n);
    next_ += n;
    return traits_type::to_int_type(*gptr());
  }

 private:
  /// Gives back the whole pages of body_ before offset `end`.
  void release(std::size_t end) {
#if defined(__linux__)  // obj::kTextGivenBack
    static const std::uintptr_t page = std::uintptr_t(::sysconf(_SC_PAGESIZE));
    const std::uintptr_t base = reinterpret_cast<std::uintptr_t>(body_.data());
    const std::uintptr_t from = (base + released_ + page - 1) / page * page;
    const std::uintptr_t to = (base + end) / page * page;
    if (to > from && ::madvise(reinterpret_cast<void*>(from), to - from, MADV_DONTNEED) == 0)
      released_ = to - base;
#else
    (void)end;
#endif
  }

  std::string& body_;
  std::size_t next_ = 0;      // body_ before this offset has been served
  std::size_t released_ = 0;  // body_ before this offset has been given back
};

/// The triangles of a planar polygon (its corners' positions, in order), as index triples into
/// the corners, wound as the polygon is. tinyobjloader's own triangulation split a concave quad
/// along its shorter diagonal even when that diagonal lies outside it, and its ear clipping
/// covered points outside a concave pentagon with triangles of both windings. A quad takes its
/// shorter diagonal when both lie inside (tinyobjloader's triangles, so convex quads keep their
/// bits), else the one inside; a larger polygon is ear-clipped in the plane of its Newell normal.
/// What cannot be clipped (a self-intersecting or degenerate polygon) is fanned from its first
/// corner, and *fanned says so.
std::vector<std::array<int, 3>> triangulate(const std::vector<glm::vec3>& p, bool* fanned) {
  const int n = static_cast<int>(p.size());
  std::vector<std::array<int, 3>> out;
  auto fan = [&](const std::vector<int>& idx) {
    for (size_t k = 1; k + 1 < idx.size(); ++k) out.push_back({idx[0], idx[k], idx[k + 1]});
  };
  if (n < 3) return out;
  if (n == 3) return {{0, 1, 2}};
  // a corner at the position of the one before it adds no edge ("f 1 2 3 3", a triangle written
  // as a quad): without it the polygon is one of fewer corners, not one that "has no area"
  std::vector<int> distinct;
  for (int i = 0; i < n; ++i)
    if (distinct.empty() || p[i] != p[distinct.back()]) distinct.push_back(i);
  while (distinct.size() > 1 && p[distinct.back()] == p[distinct.front()]) distinct.pop_back();
  if (distinct.size() >= 3 && static_cast<int>(distinct.size()) < n) {
    std::vector<glm::vec3> fewer;
    for (int i : distinct) fewer.push_back(p[i]);
    for (const std::array<int, 3>& t : triangulate(fewer, fanned))
      out.push_back({distinct[t[0]], distinct[t[1]], distinct[t[2]]});
    return out;
  }
  glm::dvec3 normal(0.0);  // Newell's: twice the polygon's vector area
  for (int i = 0; i < n; ++i) normal += glm::cross(glm::dvec3(p[i]), glm::dvec3(p[(i + 1) % n]));
  const glm::dvec3 an = glm::abs(normal);
  const int axis = an.x >= an.y && an.x >= an.z ? 0 : (an.y >= an.z ? 1 : 2);
  std::vector<glm::dvec2> q(n);  // the corners in the plane, counter-clockwise
  const double flip = normal[axis] < 0 ? -1.0 : 1.0;
  for (int i = 0; i < n; ++i) {
    const glm::dvec3 v(p[i]);
    q[i] = glm::dvec2(v[(axis + 1) % 3], flip * v[(axis + 2) % 3]);
  }
  auto turn = [&](int a, int b, int c) {  // > 0: a, b, c counter-clockwise
    const glm::dvec2 u = q[b] - q[a], w = q[c] - q[a];
    return u.x * w.y - u.y * w.x;
  };
  std::vector<int> idx(n);
  for (int i = 0; i < n; ++i) idx[i] = i;
  if (!(an[axis] > 0) || !std::isfinite(an[axis])) {
    *fanned = true;
    fan(idx);
    return out;
  }
  if (n == 4) {
    const glm::vec3 e02 = p[2] - p[0], e13 = p[3] - p[1];
    const bool in02 = turn(0, 1, 2) > 0 && turn(0, 2, 3) > 0;
    const bool in13 = turn(0, 1, 3) > 0 && turn(1, 2, 3) > 0;
    const bool short02 = glm::dot(e02, e02) < glm::dot(e13, e13);
    if (in02 && (short02 || !in13)) return {{0, 1, 2}, {0, 2, 3}};
    if (in13) return {{0, 1, 3}, {1, 2, 3}};
    *fanned = true;
    fan(idx);
    return out;
  }
  auto inside = [&](int j, int a, int b, int c) {  // j in triangle a b c, edges included
    if (q[j] == q[a] || q[j] == q[b] || q[j] == q[c]) return false;
    return turn(a, b, j) >= 0 && turn(b, c, j) >= 0 && turn(c, a, j) >= 0;
  };
  // at most 255 corners (the OBJ check), but each ear is tested against the corners left: a
  // budget keeps a pathological polygon from taking seconds
  long budget = 16L * n * n;  // a convex polygon takes about n^2 / 2
  while (idx.size() > 3) {
    const int m = static_cast<int>(idx.size());
    int ear = -1;
    for (int k = 0; k < m && ear < 0; ++k) {
      const int a = idx[(k + m - 1) % m], b = idx[k], c = idx[(k + 1) % m];
      if (!(turn(a, b, c) > 0)) continue;
      bool empty = true;
      for (int j : idx) {
        if (--budget < 0) break;
        if (j != a && j != b && j != c && inside(j, a, b, c)) {
          empty = false;
          break;
        }
      }
      if (budget < 0) break;
      if (empty) ear = k;
    }
    if (ear < 0) {
      *fanned = true;
      fan(idx);
      return out;
    }
    out.push_back({idx[(ear + m - 1) % m], idx[ear], idx[(ear + 1) % m]});
    idx.erase(idx.begin() + ear);
  }
  // the last three corners are no ear: in a polygon that cuts itself (a pentagram) they can wind
  // the other way, a triangle facing backwards without a word. Such a polygon is fanned, and said.
  if (turn(idx[0], idx[1], idx[2]) < 0) {
    *fanned = true;
    out.clear();
    idx.resize(n);
    for (int i = 0; i < n; ++i) idx[i] = i;
    fan(idx);
    return out;
  }
  out.push_back({idx[0], idx[1], idx[2]});
  return out;
}

/// Frees what `v` holds (clear() keeps its capacity).
template <typename T>
void release(std::vector<T>& v) {
  std::vector<T>().swap(v);
}

/// ":<line>" of the OBJ file's vertex `i` (0-based), or "" when it cannot be found: the file is
/// read again, the text tinyobjloader read having been given back as it was read (only an error
/// needs the line).
std::string vertex_line(const std::string& path, const io::ReadSpec& spec, long i) {
  long line = 0;
  try {
    line = obj::line_of_statement(io::read_file(path, spec), "v", i);
  } catch (const Error&) {
  }
  return line > 0 ? ":" + std::to_string(line) : "";
}

/// The capacity grow_for gives a vector of `capacity` that must hold `need`.
std::uint64_t grown_capacity(std::uint64_t capacity, std::uint64_t need) {
  return capacity >= need ? capacity : std::max(need, capacity + capacity / 2);
}

/// Makes room in `v` for `more` elements at once: one allocation per mesh, by at least half again
/// (amortised over many meshes), and never the slack of doubling for one large mesh.
template <typename T>
void grow_for(std::vector<T>& v, std::size_t more) {
  v.reserve(std::size_t(grown_capacity(v.capacity(), v.size() + more)));
}

}  // namespace

namespace obj {

MeshLoadBytes mesh_load_bytes(const Scene& scene, std::uint64_t text_bytes, const TextCounts& c) {
  const std::uint64_t v = std::uint64_t(c.vertices), n = std::uint64_t(c.normals),
                      t = std::uint64_t(c.texcoords), tri = std::uint64_t(c.triangles);
  // the scene's arrays as they are held, and as they grow to take this mesh (grow_for: the old
  // block and the new one at once)
  MeshLoadBytes b;
  auto add = [&](std::uint64_t capacity, std::uint64_t size, std::uint64_t more,
                 std::uint64_t bytes) {
    b.held += capacity * bytes;
    b.grown += grown_capacity(capacity, size + more) * bytes;
  };
  add(scene.positions.capacity(), scene.positions.size(), v, sizeof(glm::dvec3));
  add(scene.normals.capacity(), scene.normals.size(), n, sizeof(glm::dvec3));
  add(scene.uvs.capacity(), scene.uvs.size(), t, sizeof(glm::dvec2));
  add(scene.triangles.capacity(), scene.triangles.size(), tri, sizeof(Triangle));
  const std::uint64_t reading =
      std::max(c.usemtl_names.empty() ? text_bytes : 2 * text_bytes, c.reading_bytes);
  // tinyobjloader's arrays as it leaves them: floats with up to as much again unused, each
  // corner's indices (12 bytes) and each element's corner count, material and smoothing group
  const std::uint64_t left =
      8 * (3 * v + 3 * n + 2 * t) + 12 * std::uint64_t(c.corners) + 9 * std::uint64_t(c.elements);
  b.need = b.held + std::max(reading, b.grown + left);
  return b;
}

}  // namespace obj

namespace {

/// Before tinyobjloader reads `path`: the scene's meshes so far and this one must stay within the
/// host limit while it loads (obj::mesh_load_bytes), and the scene's vertices and triangles
/// within the int indices of its triangles. Each OBJ file is bounded, not their number: twelve
/// copies of a 10^6-triangle soup under a 2 GB limit loaded for 14 s and ended in a bare "out of
/// memory".
void check_mesh_memory(const Scene& scene, const std::string& path, std::uint64_t text_bytes,
                       const obj::TextCounts& c) {
  const std::uint64_t v = std::uint64_t(c.vertices), n = std::uint64_t(c.normals),
                      t = std::uint64_t(c.texcoords), tri = std::uint64_t(c.triangles);
  constexpr std::uint64_t kMaxIndex = std::uint64_t(std::numeric_limits<int>::max());
  if (scene.positions.size() + v > kMaxIndex || scene.normals.size() + n > kMaxIndex ||
      scene.uvs.size() + t > kMaxIndex || scene.triangles.size() + tri > kMaxIndex / 2)
    throw Error(path + ": with this mesh the scene has more than " + std::to_string(kMaxIndex) +
                " vertices, normals or texture coordinates, or " + std::to_string(kMaxIndex / 2) +
                " triangles: reduce the meshes' size or number");
  const obj::MeshLoadBytes b = obj::mesh_load_bytes(scene, text_bytes, c);
  std::string what;
  const std::uint64_t limit = sys::host_memory_allowed(&what);
  if (limit > 0 && b.need > limit)
    throw Error(path + ": with this mesh (" + std::to_string(tri) +
                " triangles) the scene's meshes need about " + sys::format_bytes(b.need) +
                " while it is read (" + sys::format_bytes(b.grown) +
                " after), more than the limit of " + sys::format_bytes(limit) + " (80% of " + what +
                "): reduce the meshes' size or number");
}

}  // namespace

std::vector<std::string> load_obj(Scene& scene, const std::string& path,
                                  const glm::dmat4& transform, int material_override,
                                  ObjMaterials* known,
                                  std::unordered_map<std::string, int>* names) {
  io::ReadSpec spec;
  spec.what = "OBJ file";
  spec.max_bytes = obj::kMaxObjBytes;
  spec.text = true;
  std::string text = io::read_file(path, spec);
  obj::strip_utf8_bom(text);
  const obj::TextCounts counts = obj::check_obj_text(path, text);  // before tinyobjloader
  check_mesh_memory(scene, path, text.size(), counts);
  const bool use_mtl = material_override < 0;
  // tinyobjloader looks a usemtl name up when it reads the statement, in the libraries read so
  // far: the reader reads all of the file's libraries at the first mtllib, and when a usemtl
  // comes before that, an mtllib line is put first (the line numbers of tinyobjloader's messages
  // are moved back by one)
  const bool head = use_mtl && counts.usemtl_before_mtllib && !counts.libraries.empty();
  const std::string first_line = head ? "mtllib libraries\n" : "";
  // "f 1 2 3 # top": tinyobjloader reads the comment as an index; "usemtl my mat": it reads the
  // first word. The comments blanked (in place), and such materials named by alias (a copy, that
  // replaces the text)
  if (counts.element_comments) obj::blank_element_comments(text);
  if (!counts.usemtl_names.empty()) text = obj::alias_usemtl(text, counts.usemtl_names);
  SpentText spent(first_line, text);  // the text is spent as tinyobjloader reads it
  std::istream in(&spent);
  obj::MtlReader reader(fs::path(path).parent_path(), counts.libraries, use_mtl,
                        counts.usemtl_names);
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> mats;
  std::string twarn, terr;
  // polygons as they are: lucent triangulates them (triangulate() above)
  bool ok = tinyobj::LoadObj(&attrib, &shapes, &mats, &twarn, &terr, &in, &reader,
                             /*triangulate=*/false, /*default_vcols_fallback=*/false);
  std::string().swap(text);  // spent
  // tinyobjloader's faces were a small array each, freed in many pieces that glibc keeps (37 MiB
  // for a 10^6-triangle soup): given back before the scene's arrays grow
  sys::return_free_memory();
  if (head) {
    twarn = obj::shift_line_numbers(twarn, 1);
    terr = obj::shift_line_numbers(terr, 1);
  }
  if (!reader.error.empty()) throw Error(reader.error);
  if (!ok) obj::throw_parse_error(path, terr);

  const long nv = static_cast<long>(attrib.vertices.size() / 3);
  const long nn = static_cast<long>(attrib.normals.size() / 3);
  const long nt = static_cast<long>(attrib.texcoords.size() / 2);
  if (nv != counts.vertices || nn != counts.normals || nt != counts.texcoords)
    throw Error(path + ": tinyobjloader read " + std::to_string(nv) + " vertices, " +
                std::to_string(nt) + " texture coordinates and " + std::to_string(nn) +
                " normals where the file has " + std::to_string(counts.vertices) + ", " +
                std::to_string(counts.texcoords) + " and " + std::to_string(counts.normals));
  // the indices were checked in the text; what tinyobjloader made of them is checked again
  for (const auto& s : shapes) {
    for (const auto& i : s.mesh.indices) {
      if (i.vertex_index < 0 || i.vertex_index >= nv || i.normal_index < -1 ||
          i.normal_index >= nn || i.texcoord_index < -1 || i.texcoord_index >= nt)
        throw Error(path + ": a face index is out of range");
    }
    size_t corners = 0;
    for (unsigned int fv : s.mesh.num_face_vertices) {
      if (fv < 3 || fv > static_cast<unsigned int>(obj::kMaxFaceVertices))
        throw Error(path + ": a face has " + std::to_string(fv) + " corners");
      corners += fv;
    }
    if (s.mesh.indices.size() != corners) throw Error(path + ": inconsistent face list");
  }

  // warnings: the missing MTL libraries, then the library's own remarks once each. Where other
  // libraries were read, only the materials the missing ones would define are lost (it said
  // every face used the default material, and the faces that named another library's material
  // had it)
  const bool some_read = reader.libraries.size() > reader.unreadable.size();
  const bool some_lost = !reader.missing.empty() || !reader.unreadable.empty();
  const std::string lost = some_read ? "; faces whose material only it would define use the "
                                       "default material"
                                     : "; faces use the default material";
  for (const std::string& m : reader.missing)
    warn(path + ": material library '" + fs::path(m).filename().string() + "' not found (" + m +
         ")" + lost);
  for (const std::string& m : reader.unreadable) warn(m + lost);
  // statements OBJ does not have, in a file that has vertices or faces (a file of none is
  // refused): a typo lost its line without a word ("f1 2 3", "fo 1 2 3": a face gone)
  if (counts.foreign_lines > 0)
    warn(path + ":" + std::to_string(counts.foreign_line) + ": '" + counts.foreign_statement +
         "' is no OBJ statement; the line is ignored" +
         (counts.foreign_lines > 1 ? " (and " + std::to_string(counts.foreign_lines - 1) +
                                         " more such line" + (counts.foreign_lines > 2 ? "s)" : ")")
                                   : std::string()));
  for (const std::string& w : reader.warnings) warn(w);
  std::set<std::string> seen;
  std::vector<std::string> unread_names;  // usemtl names no library read defines, one not read
  for (const std::string& w : lines_of(twarn + terr)) {
    if (!seen.insert(w).second) continue;
    if (w.rfind("Failed to load material file", 0) == 0) continue;  // reported above
    if (w.rfind("material [", 0) == 0) {
      // (with no library read, the warnings above say it all)
      if (!use_mtl || (some_lost && !some_read)) continue;
      size_t a = w.find('\''), b = w.rfind('\'');
      std::string name = (a != std::string::npos && b > a) ? w.substr(a + 1, b - a - 1) : w;
      for (size_t k = 0; k < counts.usemtl_names.size(); ++k)
        if (name == obj::usemtl_alias(k)) name = counts.usemtl_names[k];
      // "newmtl red # note" defines 'red # note', which "usemtl red" does not name
      std::string hint;
      for (const tinyobj::material_t& m : mats) {
        if (m.name.size() <= name.size() + 1 || m.name.compare(0, name.size(), name) != 0 ||
            (m.name[name.size()] != ' ' && m.name[name.size()] != '\t') ||
            obj::trim(m.name.substr(name.size()))[0] != '#')
          continue;
        hint = " (the MTL file defines '" + m.name +
               "': a '#' on a newmtl line is part of the name, not a comment)";
        break;
      }
      if (some_lost) {  // (one line for them all: the library not read may define each)
        unread_names.push_back(name);
        continue;
      }
      warn(path + ": usemtl '" + name +
           (counts.libraries.empty() ? "' but the file names no material library (mtllib)"
                                     : "' names no material of the MTL file") +
           hint + "; faces use the default material");
      continue;
    }
    warn(path + ": " + w);
  }
  if (!unread_names.empty()) {
    const std::string list = obj::first_items(
        unread_names.size(), 4, [&](std::size_t k) { return "'" + unread_names[k] + "'"; });
    warn(path + ": usemtl " + list + (unread_names.size() == 1 ? " names" : " name") +
         " no material of the MTL files read (a library was not read, above); faces use the "
         "default material");
  }

  // The scene's arrays are filled in the order that holds the least at once: normals and texture
  // coordinates, each array of tinyobjloader's freed once converted; the faces, each shape's
  // arrays freed once converted; the positions last (the faces' polygons read tinyobjloader's).
  // The vertices are checked first, so that an error comes before any face is converted.
  const glm::dmat3 nxf = scene_detail::normal_transform(glm::dmat3(transform));
  const bool mirrored = scene_detail::unit_determinant(glm::dmat3(transform)) < 0;
  const int vbase = static_cast<int>(scene.positions.size());
  const int nbase = static_cast<int>(scene.normals.size());
  const int tbase = static_cast<int>(scene.uvs.size());
  auto world = [&](long i) {
    const glm::dvec3 p(attrib.vertices[3 * i], attrib.vertices[3 * i + 1],
                       attrib.vertices[3 * i + 2]);
    return glm::dvec3(transform * glm::dvec4(p, 1.0));
  };
  for (long i = 0; i < nv; ++i) {
    // a vertex (after the transform) beyond the geometry range is refused: the kernel's float
    // arithmetic would make it vanish (lucent/limits.hpp)
    const glm::dvec3 w = world(i);
    if (!(max_abs(w) <= limits::kMaxCoordinate)) {
      std::ostringstream where;
      where << "vertex " << i + 1 << " (" << w.x << ", " << w.y << ", " << w.z << ")"
            << (transform == glm::dmat4(1.0) ? "" : " after the transform");
      throw Error(path + vertex_line(path, spec, i) + ": " + beyond_geometry_range(where.str()));
    }
  }
  // room for the mesh at once (growing by doubling held up to three times the vertices at once)
  grow_for(scene.positions, std::size_t(nv));
  grow_for(scene.normals, std::size_t(nn));
  grow_for(scene.uvs, std::size_t(nt));
  grow_for(scene.triangles, std::size_t(counts.triangles));
  std::vector<bool> normal_ok(nn);
  for (long i = 0; i < nn; ++i) {
    glm::dvec3 n = nxf * glm::dvec3(attrib.normals[3 * i], attrib.normals[3 * i + 1],
                                    attrib.normals[3 * i + 2]);
    glm::dvec3 u = unit(n);
    double len = glm::length(u);  // 1, or 0 or not finite for a normal that has no direction
    normal_ok[i] = len > 0 && std::isfinite(len);
    scene.normals.push_back(normal_ok[i] ? u : glm::dvec3(0.0));
  }
  release(attrib.normals);
  for (long i = 0; i < nt; ++i)
    scene.uvs.push_back({attrib.texcoords[2 * i], attrib.texcoords[2 * i + 1]});
  release(attrib.texcoords);

  // faces
  ObjMaterials own;  // without SceneBuilder's: the scene's textures are shared all the same
  if (!known)
    for (size_t i = 0; i < scene.textures.size(); ++i)
      own.emplace(texture_file_key(scene.textures[i].path), static_cast<int>(i));
  obj::MaterialMapper mapper(scene, known ? *known : own, names, path, mats, reader.origin,
                             reader.definition);
  size_t faces = 0, fanned_faces = 0;
  std::vector<glm::vec3> corners;
  std::vector<std::array<int, 3>> tris;
  for (auto& s : shapes) {
    size_t first = 0;  // the face's first index
    for (size_t f = 0; f < s.mesh.num_face_vertices.size(); ++f) {
      const unsigned int fv = s.mesh.num_face_vertices[f];
      const tinyobj::index_t* face = &s.mesh.indices[first];
      first += fv;
      bool fanned = false;
      if (fv > 3) {
        corners.clear();
        for (unsigned int k = 0; k < fv; ++k) {
          const float* v = &attrib.vertices[3 * size_t(face[k].vertex_index)];
          corners.emplace_back(v[0], v[1], v[2]);
        }
        tris = triangulate(corners, &fanned);
      } else {
        tris.assign(1, {0, 1, 2});  // a triangle is itself (as triangulate() makes it)
      }
      for (const std::array<int, 3>& tri : tris) {
        const tinyobj::index_t idx[3] = {face[tri[0]], face[tri[1]], face[tri[2]]};
        Triangle t;
        bool has_n = true, has_uv = true;
        for (int k = 0; k < 3; ++k) {
          t.v[k] = vbase + idx[k].vertex_index;
          has_n = has_n && idx[k].normal_index >= 0 && normal_ok[idx[k].normal_index];
          has_uv = has_uv && idx[k].texcoord_index >= 0;
        }
        for (int k = 0; k < 3; ++k) {
          t.n[k] = has_n ? nbase + idx[k].normal_index : -1;
          t.uv[k] = has_uv ? tbase + idx[k].texcoord_index : -1;
        }
        if (mirrored) {
          std::swap(t.v[1], t.v[2]);
          std::swap(t.n[1], t.n[2]);
          std::swap(t.uv[1], t.uv[2]);
        }
        t.material = use_mtl
                         ? mapper.get(f < s.mesh.material_ids.size() ? s.mesh.material_ids[f] : -1)
                         : material_override;
        scene.triangles.push_back(t);
        ++faces;
      }
      fanned_faces += fanned;
    }
    s.mesh = tinyobj::mesh_t();  // converted: its index arrays are freed
  }
  for (long i = 0; i < nv; ++i) scene.positions.push_back(world(i));
  release(attrib.vertices);
  if (faces == 0) warn(path + ": no faces");
  if (fanned_faces > 0)
    warn(path + ": " + std::to_string(fanned_faces) +
         " polygon(s) that cut themselves or have no area were split as fans from their first "
         "corner");
  return reader.libraries;
}

}  // namespace lucent::scene_detail
