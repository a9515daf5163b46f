// OBJ meshes through tinyobjloader: the file read with a bound and its text checked first
// (obj_check.cpp), faces triangulated by the library and appended to the scene's world-space
// triangle list, MTL materials mapped by obj_mtl.cpp (docs/obj-mtl.md).
#include <tiny_obj_loader.h>

#include <cmath>
#include <set>
#include <sstream>
#include <streambuf>

#include "core/file_io.hpp"
#include "lucent/error.hpp"
#include "scene/loaders.hpp"
#include "scene/obj_internal.hpp"
#include "scene/validate.hpp"

namespace lucent::scene_detail {

namespace fs = std::filesystem;
using obj::lines_of;

namespace {

// Serves `head`, then `body`, to tinyobjloader without copying them.
class JoinedText : public std::streambuf {
 public:
  JoinedText(const std::string& head, const std::string& body) : body_(body) {
    char* h = const_cast<char*>(head.data());
    setg(h, h, h + head.size());
  }

 protected:
  int_type underflow() override {
    if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
    if (in_body_ || body_.empty()) return traits_type::eof();
    in_body_ = true;
    char* b = const_cast<char*>(body_.data());
    setg(b, b, b + body_.size());
    return traits_type::to_int_type(*gptr());
  }

 private:
  const std::string& body_;
  bool in_body_ = false;
};

}  // namespace

std::vector<std::string> load_obj(Scene& scene, const std::string& path,
                                  const glm::dmat4& transform, int material_override,
                                  ObjMaterials* known) {
  io::ReadSpec spec;
  spec.what = "OBJ file";
  spec.max_bytes = obj::kMaxObjBytes;
  spec.text = true;
  const std::string text = io::read_file(path, spec);
  const obj::TextCounts counts = obj::check_obj_text(path, text);  // before tinyobjloader
  const bool use_mtl = material_override < 0;
  // tinyobjloader looks a usemtl name up when it reads the statement, in the libraries read so
  // far: the reader reads all of the file's libraries at the first mtllib, and when a usemtl
  // comes before that, an mtllib line is put first (the line numbers of tinyobjloader's messages
  // are moved back by one)
  const bool head = use_mtl && counts.usemtl_before_mtllib && !counts.libraries.empty();
  const std::string first_line = head ? "mtllib libraries\n" : "";
  JoinedText joined(first_line, text);
  std::istream in(&joined);
  obj::MtlReader reader(fs::path(path).parent_path(), counts.libraries, use_mtl);
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> mats;
  std::string twarn, terr;
  bool ok = tinyobj::LoadObj(&attrib, &shapes, &mats, &twarn, &terr, &in, &reader,
                             /*triangulate=*/true, /*default_vcols_fallback=*/false);
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
        throw Error(path + ": a face index is out of range after triangulation");
    }
    for (unsigned int fv : s.mesh.num_face_vertices)
      if (fv != 3) throw Error(path + ": a face could not be triangulated");
    if (s.mesh.indices.size() != 3 * s.mesh.num_face_vertices.size())
      throw Error(path + ": inconsistent face list after triangulation");
  }

  // warnings: the missing MTL libraries, then the library's own remarks once each
  for (const std::string& m : reader.missing)
    warn(path + ": material library '" + fs::path(m).filename().string() + "' not found (" + m +
         "); faces use the default material");
  for (const std::string& m : reader.unreadable) warn(m + "; faces use the default material");
  for (const std::string& w : reader.warnings) warn(w);
  std::set<std::string> seen;
  for (const std::string& w : lines_of(twarn + terr)) {
    if (!seen.insert(w).second) continue;
    if (w.rfind("Failed to load material file", 0) == 0) continue;  // reported above
    if (w.rfind("material [", 0) == 0) {
      if (!use_mtl || !reader.missing.empty() || !reader.unreadable.empty()) continue;
      size_t a = w.find('\''), b = w.rfind('\'');
      std::string name = (a != std::string::npos && b > a) ? w.substr(a + 1, b - a - 1) : w;
      warn(path + ": usemtl '" + name +
           (counts.libraries.empty() ? "' but the file names no material library (mtllib)"
                                     : "' names no material of the MTL file") +
           "; faces use the default material");
      continue;
    }
    warn(path + ": " + w);
  }

  // vertices
  const glm::dmat3 nxf = glm::transpose(glm::inverse(glm::dmat3(transform)));
  const bool mirrored = glm::determinant(glm::dmat3(transform)) < 0;
  const int vbase = static_cast<int>(scene.positions.size());
  const int nbase = static_cast<int>(scene.normals.size());
  const int tbase = static_cast<int>(scene.uvs.size());
  for (long i = 0; i < nv; ++i) {
    glm::dvec3 p(attrib.vertices[3 * i], attrib.vertices[3 * i + 1], attrib.vertices[3 * i + 2]);
    glm::dvec3 w = glm::dvec3(transform * glm::dvec4(p, 1.0));
    // a vertex (after the transform) beyond the geometry range is refused: the kernel's float
    // arithmetic would make it vanish (lucent/limits.hpp)
    if (!(max_abs(w) <= limits::kMaxCoordinate)) {
      std::ostringstream where;
      where << "vertex " << i + 1 << " (" << w.x << ", " << w.y << ", " << w.z << ")"
            << (transform == glm::dmat4(1.0) ? "" : " after the transform");
      throw Error(path + ":" + std::to_string(obj::line_of_statement(text, "v", i)) + ": " +
                  beyond_geometry_range(where.str()));
    }
    scene.positions.push_back(w);
  }
  std::vector<bool> normal_ok(nn);
  for (long i = 0; i < nn; ++i) {
    glm::dvec3 n = nxf * glm::dvec3(attrib.normals[3 * i], attrib.normals[3 * i + 1],
                                    attrib.normals[3 * i + 2]);
    double len = glm::length(n);
    normal_ok[i] = len > 0 && std::isfinite(len);
    scene.normals.push_back(normal_ok[i] ? n / len : glm::dvec3(0.0));
  }
  for (long i = 0; i < nt; ++i)
    scene.uvs.push_back({attrib.texcoords[2 * i], attrib.texcoords[2 * i + 1]});

  // faces
  ObjMaterials own;
  obj::MaterialMapper mapper(scene, known ? *known : own, path, mats, reader.origin);
  size_t faces = 0;
  for (const auto& s : shapes) {
    for (size_t f = 0; f < s.mesh.num_face_vertices.size(); ++f) {
      const tinyobj::index_t* idx = &s.mesh.indices[3 * f];
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
  }
  if (faces == 0) warn(path + ": no faces");
  return reader.libraries;
}

}  // namespace lucent::scene_detail
