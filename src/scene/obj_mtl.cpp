// MTL libraries: read with a bound, their numbers checked (obj_check.cpp), and their materials
// mapped to lucent materials as docs/obj-mtl.md describes.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <locale>
#include <set>
#include <sstream>

#include "core/file_io.hpp"
#include "lucent/error.hpp"
#include "scene/loaders.hpp"
#include "scene/obj_internal.hpp"
#include "scene/validate.hpp"

namespace lucent::scene_detail::obj {

namespace fs = std::filesystem;

namespace {

constexpr const char* kDefaultMaterial = "obj:default";

glm::dvec3 rgb(const tinyobj::real_t* c) { return {c[0], c[1], c[2]}; }
double max3(const glm::dvec3& c) { return std::max(c.x, std::max(c.y, c.z)); }

// A texture named in an MTL file, relative to that file's directory.
fs::path texture_path(const std::string& mtl_path, const std::string& name) {
  return named_file(fs::path(mtl_path).parent_path(), name);
}

/// Where a texture named by a path that is not found (another machine's: `C:\Users\me\q.png`,
/// `/home/me/q.png`) is looked for next, as Blender's importer does: its file name beside the MTL
/// file; "" when there is no such other file.
fs::path texture_beside(const std::string& mtl_path, const std::string& name) {
  const std::size_t cut = name.find_last_of("/\\");
  if (cut == std::string::npos || cut + 1 >= name.size()) return {};
  const std::string file = name.substr(cut + 1);
  if (file == "." || file == "..") return {};
  const fs::path p = fs::path(mtl_path).parent_path() / file;
  std::error_code ec;
  return fs::is_regular_file(p, ec) ? p : fs::path();  // (a directory there is no texture)
}

}  // namespace

bool MtlReader::operator()(const std::string&, std::vector<tinyobj::material_t>* materials,
                           std::map<std::string, int>* map, std::string*, std::string*) {
  // tinyobjloader calls at each mtllib statement, and reads one library of a statement naming
  // several: all of them are read at the first call
  if (!enabled_ || done_) return true;
  done_ = true;
  std::set<std::string> seen;  // canonical paths: a library named twice is read once
  for (const std::string& name : names_) {
    const fs::path p = named_file(dir_, name);
    std::error_code ec;
    fs::path canonical = fs::weakly_canonical(p, ec);
    if (!seen.insert(ec ? p.string() : canonical.string()).second) continue;
    if (!read(p.string(), materials, map)) break;
  }
  add_aliases(map);
  return true;
}

void MtlReader::add_aliases(std::map<std::string, int>* map) const {
  for (std::size_t k = 0; k < usemtl_names_.size(); ++k) {
    const std::string& name = usemtl_names_[k];
    auto it = map->find(name);
    // "usemtl red # note" where no material has that whole name: the name before the comment,
    // as tinyobjloader read it (its first word) before names could have spaces
    for (std::size_t hash = name.find('#'); it == map->end() && hash != std::string::npos;
         hash = name.find('#', hash + 1)) {
      if (hash == 0 || (name[hash - 1] != ' ' && name[hash - 1] != '\t')) continue;
      const std::string before = trim(name.substr(0, hash));
      if (!before.empty()) it = map->find(before);
      break;
    }
    if (it != map->end()) (*map)[usemtl_alias(k)] = it->second;
  }
}

bool MtlReader::read(const std::string& path, std::vector<tinyobj::material_t>* materials,
                     std::map<std::string, int>* map) {
  std::string text;
  try {
    io::ReadSpec spec;
    spec.what = "MTL file";
    spec.max_bytes = kMaxMtlBytes;
    spec.text = true;
    text = io::read_file(path, spec);
  } catch (const Error& e) {
    // (a path that cannot be looked at, a symbolic link loop, is unreadable, not missing: it was
    // "not found")
    std::error_code ec;
    if (!fs::exists(path, ec) && !ec) {
      missing.push_back(path);
    } else {
      libraries.push_back(path);
      unreadable.push_back(e.what());
    }
    return true;
  }
  libraries.push_back(path);
  strip_utf8_bom(text);
  try {
    check_mtl_text(path, text);
  } catch (const Error& e) {
    error = e.what();
    return false;
  }
  text = read_colour_forms(path, text, &warnings);
  // a name defined again (in this library or an earlier one): tinyobjloader keeps the first
  const std::vector<MtlName> names = mtl_material_names(text);
  for (const MtlName& m : names) {
    auto [first, added] = defined_.insert({m.name, {path, m.line}});
    if (added) continue;
    const auto& [first_path, first_line] = first->second;
    warnings.push_back(path + ":" + std::to_string(m.line) + ": material '" + m.name +
                       "' is defined again (first at " +
                       (first_path == path ? "line " : first_path + ":") +
                       std::to_string(first_line) + "); faces use the first definition");
  }
  std::vector<IgnoredOption> ignored;
  std::istringstream in(strip_texture_options(text, &ignored));
  // the textures would render otherwise than the file asks, without a word: one line per file
  // (an exporter may write an option on every material), its first options and their lines
  if (!ignored.empty()) {
    const std::string list = first_items(ignored.size(), 4, [&](std::size_t i) {
      return "'" + ignored[i].option + "' (line " + std::to_string(ignored[i].line) + ")";
    });
    warnings.push_back(path + ": map_Kd options that lucent does not support are ignored: " + list +
                       " (of map_Kd's options lucent reads -s, -o and -clamp; the image is "
                       "otherwise used as decoded)");
  }
  size_t before = materials->size();
  std::string mtl_warn, mtl_err;
  tinyobj::LoadMtl(map, materials, &in, &mtl_warn, &mtl_err);
  for (size_t i = before; i < materials->size(); ++i) {
    origin.push_back(path);
    // one material per newmtl, in order (a file without any: one unnamed material)
    definition.push_back(i - before < names.size() ? names[i - before] : MtlName{});
    // tinyobjloader keeps the spaces after "newmtl " ("newmtl  red" is " red"): a name is trimmed
    // as usemtl's is (the first definition of a name keeps it)
    tinyobj::material_t& m = (*materials)[i];
    const std::string trimmed = trim(m.name);
    if (trimmed == m.name) continue;
    auto it = map->find(m.name);
    if (it != map->end() && it->second == static_cast<int>(i)) map->erase(it);
    m.name = trimmed;
    map->emplace(trimmed, static_cast<int>(i));
  }
  for (const std::string& w : lines_of(mtl_warn + mtl_err)) warnings.push_back(path + ": " + w);
  return true;
}

MaterialMapper::MaterialMapper(Scene& scene, ObjMaterials& known,
                               std::unordered_map<std::string, int>* names,
                               const std::string& obj_path,
                               const std::vector<tinyobj::material_t>& mats,
                               const std::vector<std::string>& origin,
                               const std::vector<MtlName>& definition)
    : scene_(scene),
      known_(known),
      mats_(mats),
      origin_(origin),
      definition_(definition),
      index_(mats.size(), -1),
      names_(names) {
  std::error_code ec;
  obj_path_ = fs::weakly_canonical(obj_path, ec);
  if (ec) obj_path_ = obj_path;
}

int MaterialMapper::get(int id) {
  if (id < 0 || id >= static_cast<int>(mats_.size())) return default_material();
  if (index_[id] < 0) index_[id] = convert(mats_[id], origin_[id], definition_[id]);
  return index_[id];
}

std::unordered_map<std::string, int>& MaterialMapper::names() {
  if (names_) return *names_;
  if (!own_made_) {
    for (std::size_t i = 0; i < scene_.materials.size(); ++i)
      own_names_.emplace(scene_.materials[i].name, static_cast<int>(i));  // the first wins
    own_made_ = true;
  }
  return own_names_;
}

int MaterialMapper::add(const Material& m) {
  const int index = static_cast<int>(scene_.materials.size());
  scene_.materials.push_back(m);
  names().emplace(m.name, index);
  return index;
}

std::string MaterialMapper::free_name(const std::string& name, bool with_path) {
  // "model.obj:paint", then "b/model.obj:paint", "a/b/model.obj:paint", ... the whole path
  std::string prefix = with_path ? obj_path_.filename().string() : "";
  fs::path dir = obj_path_.parent_path();
  for (;;) {
    std::string candidate = with_path ? prefix + ":" + name : name;
    if (!names().count(candidate)) return candidate;
    if (!with_path || dir.empty() || dir == dir.parent_path()) break;
    prefix = (dir.filename() / prefix).generic_string();
    if (dir.parent_path() == dir.root_path()) prefix = dir.root_path().generic_string() + prefix;
    dir = dir.parent_path();
  }
  const std::string base = with_path ? obj_path_.filename().string() + ":" + name : name;
  for (int n = 2;; ++n) {
    std::string candidate = base + "#" + std::to_string(n);
    if (!names().count(candidate)) return candidate;
  }
}

void MaterialMapper::check_converted(const Material& m, const std::string& mtl_path,
                                     const MtlName& def) const {
  // the scene's checks (validate_material), named by the MTL file, the material's line and the
  // statement a value came from: validate_scene reported "s.json: /materials/m.obj:red/ior: must
  // be in [0.05, 20], got 1000", a place of no file
  const std::string head = "material '" + def.name + "'";
  try {
    validate_material(m, scene_.textures, Reporter("", head));
  } catch (const Error& e) {
    // "material 'red'/ior: must be ..." -> "ior (Ni): must be ..."; "/albedo/1" -> "albedo/1 (Kd)"
    const std::string what = e.what();
    const std::size_t at = what.find(head);
    std::string rest = at == std::string::npos ? what : what.substr(at + head.size());
    const std::size_t colon = rest.find(": ");
    std::string key = rest.substr(0, colon),
                tail = colon == std::string::npos ? "" : rest.substr(colon);
    static const std::pair<const char*, const char*> kFrom[] = {
        {"/ior", "Ni"},  {"/albedo", "Kd"},   {"/specular", "Ks"}, {"/reflectance", "Ks"},
        {"/tint", "Tf"}, {"/emission", "Ke"}, {"/roughness", "Ns"}};
    // map_Kd's -s and -o, at the map_Kd's line: "albedo/uv_scale/0 (map_Kd -s)"
    long line = def.line;
    const bool option = key.rfind("/albedo/uv_", 0) == 0;
    if (option) {
      key += key.rfind("/albedo/uv_scale", 0) == 0 ? " (map_Kd -s)" : " (map_Kd -o)";
      line = def.kd_line;
    }
    for (const auto& [name, tag] : kFrom)
      if (!option && key.substr(0, key.find('/', 1)) == name) key += std::string(" (") + tag + ")";
    if (!key.empty() && key[0] == '/') key.erase(0, 1);
    throw Error(mtl_path + ":" + std::to_string(line) + ": " + head +
                (key.empty() ? "" : ": " + key) + tail);
  }
}

int MaterialMapper::default_material() {
  if (default_ < 0) {
    auto it = known_.find(kDefaultMaterial);
    if (it != known_.end()) {
      default_ = it->second;
    } else {
      Material m;
      m.name = free_name(kDefaultMaterial, false);
      m.type = MaterialType::Diffuse;
      m.albedo = glm::dvec3(0.8);
      default_ = add(m);
      known_[kDefaultMaterial] = default_;
    }
  }
  return default_;
}

int MaterialMapper::convert(const tinyobj::material_t& t, const std::string& mtl_path,
                            const MtlName& def) {
  // the same MTL material (library by canonical path, and name) made before: by this OBJ loaded
  // again, or another naming the same library
  std::error_code ec;
  fs::path library = fs::weakly_canonical(mtl_path, ec);
  const std::string key = (ec ? mtl_path : library.string()) + "\n" + t.name;
  if (auto it = known_.find(key); it != known_.end()) return it->second;

  Material m;
  m.name = free_name(t.name, true);
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
    // why it is transparent, for the warnings
    std::ostringstream why;
    why.imbue(std::locale::classic());  // "0.5", whatever the global locale
    if (t.dissolve < 1)
      why << "opacity " << t.dissolve << " (d or Tr)";
    else
      why << "illum " << illum;
    const std::string at = mtl_path + ":" + std::to_string(def.tf_line) + ": material '" + t.name +
                           "' (transparent: " + why.str() + ")";
    // Tf, the transmission filter, is the tint of the light that passes (the MTL specification;
    // 3ds Max writes its filter colour). A grey Tf other than 1 has two readings: the fraction
    // let through (the specification), or one minus it (3ds Max's import and G3D, for which
    // McGuire's Cornell boxes write Tf 0.10 on their glass and water); some exporters write
    // Tf 0 0 0 on every material. Every grey Tf seen on a transparent material meant clear
    const glm::dvec3 tf = rgb(t.transmittance);
    if (def.tf_line > 0 && !def.tf_numbers) {
      warn(at + ": " + def.tf_tag + " spectral (a curve) is not read; tint 1");
    } else if (def.tf_line > 0 && tf.x == tf.y && tf.y == tf.z) {
      if (tf.x != 1) {
        std::ostringstream g;
        g.imbue(std::locale::classic());
        g << tf.x;
        warn(at + ": Tf " + g.str() + " " + g.str() + " " + g.str() +
             " is grey, which readers take as the light let through or as one minus it; taken "
             "as clear (tint 1): a Tf of unequal channels is the tint");
      }
    } else if (def.tf_line > 0) {
      m.specular = tf;
    }
    if (!t.diffuse_texname.empty())
      warn(mtl_path + ":" + std::to_string(def.line) + ": material '" + t.name +
           "' (transparent: " + why.str() +
           ") becomes a dielectric, which has no texture: its map_Kd '" + t.diffuse_texname +
           "' is ignored (Tf gives its tint)");
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
    std::error_code ec;
    if (!fs::exists(p, ec) && !ec) {
      if (fs::path beside = texture_beside(mtl_path, t.diffuse_texname); !beside.empty()) {
        // (once per name: an exporter's library names every texture so, material by material)
        if (warned_.insert(mtl_path + "\n" + t.diffuse_texname).second)
          warn(where + ": map_Kd texture '" + t.diffuse_texname + "' not found (" + p.string() +
               "); using " + beside.string() + ", its file name beside the MTL file");
        p = beside;
      }
    }
    if (!fs::exists(p, ec) && !ec) {
      warn(where + ": map_Kd texture '" + t.diffuse_texname + "' not found (" + p.string() +
           "); using Kd");
    } else {
      try {
        m.albedo_texture = load_texture(scene_, p.string(), &known_);
        m.albedo = glm::dvec3(1.0);
        // map_Kd's -s, -o and -clamp (docs/obj-mtl.md): uv * scale + offset, clamped to edge
        m.albedo_uv_scale = def.kd_scale;
        m.albedo_uv_offset = def.kd_offset;
        if (def.kd_clamp) m.albedo_wrap_u = m.albedo_wrap_v = TextureWrap::Clamp;
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
    std::error_code ec;
    if (!fs::exists(p, ec) && texture_beside(mtl_path, *file).empty() &&
        warned_.insert(p.string()).second)
      warn(where + ": " + key + " texture '" + *file + "' not found (" + p.string() +
           "); ignored (lucent does not use " + key + ")");
  }

  check_converted(m, mtl_path, def);
  known_[key] = add(m);
  return known_[key];
}

}  // namespace lucent::scene_detail::obj
