// OBJ/MTL meshes through tinyobjloader: faces triangulated by the library, appended to the scene's
// world-space triangle list; MTL materials mapped to lucent materials as docs/obj-mtl.md describes.
#include <tiny_obj_loader.h>

#include <algorithm>
#include <charconv>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "lucent/error.hpp"
#include "scene/loaders.hpp"

namespace lucent::scene_detail {

namespace fs = std::filesystem;

namespace {

constexpr const char* kDefaultMaterial = "obj:default";

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    size_t b = line.find_first_not_of(" \t\r."), e = line.find_last_not_of(" \t\r");
    if (b == std::string::npos) continue;  // tinyobjloader's stray "." lines
    out.push_back(line.substr(b, e - b + 1));
  }
  return out;
}

// Reads the libraries named by `mtllib` (relative to the OBJ's directory) and remembers which file
// each material came from, since texture paths are relative to it. Missing libraries are recorded
// (the caller warns); when disabled (a material override) nothing is read.
class MtlReader : public tinyobj::MaterialReader {
 public:
  MtlReader(fs::path dir, bool enabled) : dir_(std::move(dir)), enabled_(enabled) {}

  bool operator()(const std::string& name, std::vector<tinyobj::material_t>* materials,
                  std::map<std::string, int>* map, std::string* warn, std::string*) override {
    if (!enabled_) return true;
    fs::path p = fs::path(name).is_absolute() ? fs::path(name) : dir_ / name;
    std::ifstream in(p, std::ios::binary);
    if (!in) {
      missing.push_back(p.string());
      return false;
    }
    size_t before = materials->size();
    std::string mtl_warn, mtl_err;
    tinyobj::LoadMtl(map, materials, &in, &mtl_warn, &mtl_err);
    for (size_t i = before; i < materials->size(); ++i) origin.push_back(p.string());
    for (const std::string& w : lines_of(mtl_warn + mtl_err))
      warnings.push_back(p.string() + ": " + w);
    (void)warn;
    return true;
  }

  std::vector<std::string> missing;   ///< libraries that could not be opened
  std::vector<std::string> origin;    ///< the library of each material, by index
  std::vector<std::string> warnings;  ///< the libraries' own warnings, prefixed with their path

 private:
  fs::path dir_;
  bool enabled_;
};

// tinyobjloader only warns about out-of-range indices (at the last line of the file): find the
// face that has one, to name its line. Called on the error path only.
std::string find_bad_face(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  long counts[3] = {0, 0, 0};  // v, vt, vn
  const char* kinds[3] = {"vertex", "texture coordinate", "normal"};
  for (long ln = 1; std::getline(in, line); ++ln) {
    std::istringstream ls(line);
    std::string tag, tok;
    ls >> tag;
    if (tag == "v") ++counts[0];
    if (tag == "vt") ++counts[1];
    if (tag == "vn") ++counts[2];
    if (tag != "f") continue;
    while (ls >> tok) {
      std::stringstream parts(tok);
      std::string part;
      for (int k = 0; k < 3 && std::getline(parts, part, '/'); ++k) {
        if (part.empty()) continue;
        long idx = std::strtol(part.c_str(), nullptr, 10);
        long resolved = idx > 0 ? idx : counts[k] + idx + 1;
        if (resolved < 1 || resolved > counts[k])
          return path + ":" + std::to_string(ln) + ": " + kinds[k] + " index " + part +
                 " is out of range (" + std::to_string(counts[k]) + " defined so far)";
      }
    }
  }
  return "";
}

// tinyobjloader reads a coordinate that is not a number ("v 1 abc 0") as 0 and a missing one as
// 0 without a word: check the v, vn and vt lines of the file's text ourselves and name the first
// bad one.
std::string find_bad_vertex_line(const std::string& path, const std::string& text) {
  std::istringstream in(text);
  std::string line;
  for (long ln = 1; std::getline(in, line); ++ln) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream ls(line);
    std::string tag, tok;
    ls >> tag;
    int need;
    const char* what;
    if (tag == "v") {
      need = 3, what = "vertex";
    } else if (tag == "vn") {
      need = 3, what = "normal";
    } else if (tag == "vt") {
      need = 1, what = "texture coordinate";
    } else {
      continue;
    }
    int n = 0;
    while (ls >> tok) {
      if (tok[0] == '#') break;
      const char* b = tok.c_str() + (tok[0] == '+' ? 1 : 0);
      const char* e = tok.c_str() + tok.size();
      double x;
      auto [ptr, ec] = std::from_chars(b, e, x);
      if (ec == std::errc::result_out_of_range) {
        return path + ":" + std::to_string(ln) + ": " + what + " line: '" + tok +
               "' is out of range";
      }
      if (ec != std::errc() || ptr != e)
        return path + ":" + std::to_string(ln) + ": " + what + " line: '" + tok +
               "' is not a number";
      ++n;
    }
    if (n < need)
      return path + ":" + std::to_string(ln) + ": " + what + " line has " + std::to_string(n) +
             " numbers, needs " + std::to_string(need);
  }
  return "";
}

[[noreturn]] void throw_parse_error(const std::string& path, const std::string& err) {
  std::vector<std::string> lines = lines_of(err);
  std::string first = lines.empty() ? "cannot parse the file" : lines.front();
  std::smatch m;
  static const std::regex line_re(R"(line:? (\d+))");
  if (std::regex_search(first, m, line_re)) {
    std::string what = first;
    if (first.find("Failed parse `f'") != std::string::npos)
      what = "malformed face: an index is 0 or not a number";
    else if (first.find("Failed parse `l'") != std::string::npos)
      what = "malformed line element: an index is 0 or not a number";
    else if (first.find("Failed parse `p'") != std::string::npos)
      what = "malformed point element: an index is 0 or not a number";
    throw Error(path + ":" + m[1].str() + ": " + what);
  }
  throw Error(path + ": " + first);
}

glm::dvec3 rgb(const tinyobj::real_t* c) { return {c[0], c[1], c[2]}; }
double max3(const glm::dvec3& c) { return std::max(c.x, std::max(c.y, c.z)); }

// A texture named in an MTL file, relative to that file's directory.
fs::path texture_path(const std::string& mtl_path, const std::string& name) {
  fs::path p(name);
  if (!p.is_absolute()) p = fs::path(mtl_path).parent_path() / p;
  if (!fs::exists(p) && name.find('\\') != std::string::npos) {  // Windows-style separators
    std::string fixed = name;
    std::replace(fixed.begin(), fixed.end(), '\\', '/');
    return texture_path(mtl_path, fixed);
  }
  return p;
}

class MaterialMapper {
 public:
  MaterialMapper(Scene& scene, const std::string& obj_path,
                 const std::vector<tinyobj::material_t>& mats,
                 const std::vector<std::string>& origin)
      : scene_(scene), mats_(mats), origin_(origin), index_(mats.size(), -1) {
    obj_name_ = fs::path(obj_path).filename().string();
  }

  /// The scene material of MTL material `id` (created on first use), or the default one.
  int get(int id) {
    if (id < 0 || id >= static_cast<int>(mats_.size())) return default_material();
    if (index_[id] < 0) index_[id] = convert(mats_[id], origin_[id]);
    return index_[id];
  }

  int default_material() {
    if (default_ < 0) {
      default_ = scene_.find_material(kDefaultMaterial);
      if (default_ < 0) {
        Material m;
        m.name = kDefaultMaterial;
        m.type = MaterialType::Diffuse;
        m.albedo = glm::dvec3(0.8);
        scene_.materials.push_back(m);
        default_ = static_cast<int>(scene_.materials.size() - 1);
      }
    }
    return default_;
  }

 private:
  int convert(const tinyobj::material_t& t, const std::string& mtl_path) {
    std::string name = obj_name_ + ":" + t.name;
    int existing = scene_.find_material(name);
    if (existing >= 0) return existing;  // the same OBJ loaded again

    Material m;
    m.name = name;
    glm::dvec3 kd = rgb(t.diffuse), ks = rgb(t.specular);
    m.albedo = kd;
    m.emission = glm::max(rgb(t.emission), glm::dvec3(0.0));
    double ior = t.ior > 1 ? t.ior : 1.5;
    bool has_ks = max3(ks) > 0;
    int illum = t.illum;
    std::string where = mtl_path + ": material '" + t.name + "'";

    if (illum == 4 || illum == 6 || illum == 7 || illum == 9 || t.dissolve < 1) {
      m.type = MaterialType::Dielectric;
      m.ior = ior;
      m.specular = glm::dvec3(1.0);
    } else if ((illum == 3 || illum == 5) && has_ks && max3(kd) <= 0.01 &&
               t.diffuse_texname.empty()) {
      m.type = MaterialType::Mirror;
      m.specular = ks;
    } else if (illum >= 2 && has_ks) {
      m.type = MaterialType::Plastic;
      m.specular = ks;
      m.ior = ior;
      m.roughness =
          std::clamp(std::sqrt(2.0 / (std::max(0.0, double(t.shininess)) + 2.0)), 1e-3, 1.0);
    } else {
      m.type = MaterialType::Diffuse;
    }

    if (!t.diffuse_texname.empty() && m.type != MaterialType::Dielectric) {
      fs::path p = texture_path(mtl_path, t.diffuse_texname);
      if (!fs::exists(p)) {
        warn(where + ": map_Kd texture '" + t.diffuse_texname + "' not found (" + p.string() +
             "); using Kd");
      } else {
        try {
          m.albedo_texture = load_texture(scene_, p.string());
          m.albedo = glm::dvec3(1.0);
        } catch (const Error& e) {
          warn(std::string(e.what()) + " (map_Kd of " + where + "); using Kd");
        }
      }
    }
    // maps lucent does not use: only a missing file is worth a word
    const std::pair<const char*, const std::string*> unused[] = {
        {"map_Ka", &t.ambient_texname},
        {"map_Ks", &t.specular_texname},
        {"map_Ns", &t.specular_highlight_texname},
        {"map_bump", &t.bump_texname},
        {"disp", &t.displacement_texname},
        {"map_d", &t.alpha_texname},
        {"refl", &t.reflection_texname},
        {"map_Ke", &t.emissive_texname},
        {"norm", &t.normal_texname},
        {"map_Pr", &t.roughness_texname},
        {"map_Pm", &t.metallic_texname},
        {"map_Ps", &t.sheen_texname}};
    for (const auto& [key, file] : unused) {
      if (file->empty()) continue;
      fs::path p = texture_path(mtl_path, *file);
      if (!fs::exists(p) && warned_.insert(p.string()).second)
        warn(where + ": " + key + " texture '" + *file + "' not found (" + p.string() +
             "); ignored (lucent does not use " + key + ")");
    }

    scene_.materials.push_back(m);
    return static_cast<int>(scene_.materials.size() - 1);
  }

  Scene& scene_;
  const std::vector<tinyobj::material_t>& mats_;
  const std::vector<std::string>& origin_;
  std::vector<int> index_;
  std::string obj_name_;
  int default_ = -1;
  std::set<std::string> warned_;
};

}  // namespace

void load_obj(Scene& scene, const std::string& path, const glm::dmat4& transform,
              int material_override) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw Error(path + ": cannot open OBJ file: is a directory");
  std::ifstream file(path, std::ios::binary);
  if (!file) throw Error(path + ": cannot open OBJ file: " + std::strerror(errno));
  // read once: tinyobjloader parses the text, find_bad_vertex_line checks it
  const std::string text{std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
  std::istringstream in(text);
  const bool use_mtl = material_override < 0;
  MtlReader reader(fs::path(path).parent_path(), use_mtl);
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> mats;
  std::string twarn, terr;
  bool ok = tinyobj::LoadObj(&attrib, &shapes, &mats, &twarn, &terr, &in, &reader,
                             /*triangulate=*/true, /*default_vcols_fallback=*/false);
  if (!ok) throw_parse_error(path, terr);
  if (std::string bad = find_bad_vertex_line(path, text); !bad.empty()) throw Error(bad);

  const long nv = static_cast<long>(attrib.vertices.size() / 3);
  const long nn = static_cast<long>(attrib.normals.size() / 3);
  const long nt = static_cast<long>(attrib.texcoords.size() / 2);
  bool bad_index = twarn.find("out of bounds") != std::string::npos ||
                   twarn.find("invalid vertex index") != std::string::npos;
  for (const auto& s : shapes) {
    for (const auto& i : s.mesh.indices) {
      if (i.vertex_index < 0 || i.vertex_index >= nv || i.normal_index < -1 ||
          i.normal_index >= nn || i.texcoord_index < -1 || i.texcoord_index >= nt)
        bad_index = true;
    }
    for (unsigned char fv : s.mesh.num_face_vertices)
      if (fv != 3) throw Error(path + ": a face could not be triangulated");
  }
  if (bad_index) {
    std::string msg = find_bad_face(path);
    throw Error(msg.empty() ? path + ": a face index is out of range" : msg);
  }

  // warnings: the missing MTL libraries, then the library's own remarks once each
  for (const std::string& m : reader.missing)
    warn(path + ": material library '" + fs::path(m).filename().string() + "' not found (" + m +
         "); faces use the default material");
  for (const std::string& w : reader.warnings) warn(w);
  std::set<std::string> seen;
  for (const std::string& w : lines_of(twarn + terr)) {
    if (!seen.insert(w).second) continue;
    if (w.rfind("Failed to load material file", 0) == 0) continue;  // reported above
    if (w.rfind("material [", 0) == 0) {
      if (!use_mtl || !reader.missing.empty()) continue;
      size_t a = w.find('\''), b = w.rfind('\'');
      std::string name = (a != std::string::npos && b > a) ? w.substr(a + 1, b - a - 1) : w;
      warn(path + ": usemtl '" + name +
           "' names no material of the MTL file; faces use the default material");
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
    scene.positions.push_back(glm::dvec3(transform * glm::dvec4(p, 1.0)));
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
  MaterialMapper mapper(scene, path, mats, reader.origin);
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
}

}  // namespace lucent::scene_detail
