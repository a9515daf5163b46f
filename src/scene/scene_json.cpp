// JSON scene loading and validation. Every problem is reported as
// "<file>: <JSON pointer>: <what is wrong>" (or "<file>:<line>:<col>: ..." for syntax errors).
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cfloat>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <set>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "lucent/error.hpp"
#include "lucent/scene.hpp"
#include "scene/json_guard.hpp"
#include "scene/loaders.hpp"

namespace lucent {

using nlohmann::json;
namespace fs = std::filesystem;

int Scene::find_material(const std::string& name) const {
  for (size_t i = 0; i < materials.size(); ++i)
    if (materials[i].name == name) return static_cast<int>(i);
  return -1;
}

namespace {

std::string type_name(const json& j) {
  switch (j.type()) {
    case json::value_t::null: return "null";
    case json::value_t::boolean: return "a boolean";
    case json::value_t::string: return "a string";
    case json::value_t::array: return "an array";
    case json::value_t::object: return "an object";
    case json::value_t::discarded: return "invalid";
    default: return "a number";
  }
}

std::string show(const json& j) {
  std::string s = j.dump();
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return s;
}

std::string format_number(double v) {
  std::ostringstream ss;
  ss << v;
  return ss.str();
}

class Parser {
 public:
  Parser(std::string file, fs::path dir) : file_(std::move(file)), dir_(std::move(dir)) {}

  [[noreturn]] void fail(const std::string& ptr, const std::string& msg) const {
    throw Error(file_ + ": " + (ptr.empty() ? "/" : ptr) + ": " + msg);
  }

  const json& require(const json& obj, const std::string& ptr, const char* key) const {
    auto it = obj.find(key);
    if (it == obj.end()) fail(ptr, std::string("missing required field '") + key + "'");
    return *it;
  }

  void check_object(const json& j, const std::string& ptr) const {
    if (!j.is_object()) fail(ptr, "must be an object, got " + type_name(j));
  }

  void check_keys(const json& obj, const std::string& ptr,
                  std::initializer_list<const char*> allowed) const {
    check_object(obj, ptr);
    for (auto it = obj.begin(); it != obj.end(); ++it) {
      bool ok = false;
      for (const char* a : allowed) ok = ok || it.key() == a;
      if (!ok) {
        std::string list;
        for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
        fail(ptr + "/" + it.key(), "unknown key (allowed: " + list + ")");
      }
    }
  }

  double number(const json& j, const std::string& ptr) const {
    if (j.is_string()) {
      // JSON has no NaN/Inf literals; strings are the usual way they sneak in
      const std::string& s = j.get_ref<const std::string&>();
      if (s == "nan" || s == "NaN" || s == "inf" || s == "Infinity" || s == "-inf" ||
          s == "-Infinity")
        fail(ptr, "must be a finite number, got " + s);
    }
    if (!j.is_number()) fail(ptr, "must be a number, got " + type_name(j) + " " + show(j));
    double v = j.get<double>();
    if (!std::isfinite(v)) fail(ptr, "must be a finite number, got " + format_number(v));
    // the device stores floats: a larger value would become infinite there
    if (std::abs(v) > FLT_MAX)
      fail(ptr, "must fit in a float (magnitude at most 3.4e38), got " + format_number(v));
    return v;
  }

  double positive(const json& j, const std::string& ptr) const {
    double v = number(j, ptr);
    if (!(v > 0)) fail(ptr, "must be > 0, got " + format_number(v));
    return v;
  }

  double non_negative(const json& j, const std::string& ptr) const {
    double v = number(j, ptr);
    if (v < 0) fail(ptr, "must be >= 0, got " + format_number(v));
    return v;
  }

  long integer(const json& j, const std::string& ptr, long lo, long hi) const {
    if (!j.is_number_integer() && !j.is_number_unsigned())
      fail(ptr, "must be an integer, got " + type_name(j) + " " + show(j));
    if (j.is_number_unsigned() && j.get<std::uint64_t>() > static_cast<std::uint64_t>(hi))
      fail(ptr, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                    std::to_string(j.get<std::uint64_t>()));
    long v = j.get<long>();
    if (v < lo || v > hi)
      fail(ptr, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                    std::to_string(v));
    return v;
  }

  std::string string(const json& j, const std::string& ptr) const {
    if (!j.is_string()) fail(ptr, "must be a string, got " + type_name(j) + " " + show(j));
    return j.get<std::string>();
  }

  std::string choice(const json& j, const std::string& ptr,
                     std::initializer_list<const char*> options) const {
    std::string s = string(j, ptr);
    std::string list;
    for (const char* o : options) {
      if (s == o) return s;
      list += std::string(list.empty() ? "" : ", ") + o;
    }
    fail(ptr, "unknown value '" + s + "' (expected one of: " + list + ")");
  }

  glm::dvec3 vec3(const json& j, const std::string& ptr) const {
    if (!j.is_array() || j.size() != 3)
      fail(ptr, "must be an array of 3 numbers, got " + type_name(j) + " " + show(j));
    return {number(j[0], ptr + "/0"), number(j[1], ptr + "/1"), number(j[2], ptr + "/2")};
  }

  glm::dvec3 colour(const json& j, const std::string& ptr) const {
    glm::dvec3 c = vec3(j, ptr);
    for (int i = 0; i < 3; ++i)
      if (c[i] < 0) fail(ptr + "/" + std::to_string(i), "must be >= 0, got " + format_number(c[i]));
    return c;
  }

  glm::dvec3 direction(const json& j, const std::string& ptr) const {
    glm::dvec3 v = vec3(j, ptr);
    if (glm::length(v) == 0) fail(ptr, "must be a non-zero vector");
    return v;
  }

  std::string resolve(const std::string& rel) const {
    fs::path p(rel);
    if (p.is_relative()) p = dir_ / p;
    return p.lexically_normal().string();
  }

  // ---------------------------------------------------------------------------------------
  void parse(const json& root, Scene& scene) {
    check_keys(root, "", {"camera", "film", "integrator", "materials", "shapes", "lights"});
    if (root.contains("camera")) parse_camera(root["camera"], "/camera", scene.camera);
    if (root.contains("film")) parse_film(root["film"], "/film", scene.film);
    if (root.contains("integrator"))
      parse_integrator(root["integrator"], "/integrator", scene.integrator);
    if (root.contains("materials")) parse_materials(root["materials"], "/materials", scene);
    if (root.contains("shapes")) {
      const json& shapes = root["shapes"];
      if (!shapes.is_array()) fail("/shapes", "must be an array, got " + type_name(shapes));
      for (size_t i = 0; i < shapes.size(); ++i)
        parse_shape(shapes[i], "/shapes/" + std::to_string(i), scene);
    }
    if (root.contains("lights")) {
      const json& lights = root["lights"];
      if (!lights.is_array()) fail("/lights", "must be an array, got " + type_name(lights));
      for (size_t i = 0; i < lights.size(); ++i)
        parse_light(lights[i], "/lights/" + std::to_string(i), scene);
    }
    if (scene.camera.focus_distance <= 0)
      scene.camera.focus_distance = glm::length(scene.camera.look_at - scene.camera.position);
  }

  void parse_camera(const json& j, const std::string& p, Camera& c) {
    check_keys(j, p, {"position", "look_at", "up", "fov", "roll", "aperture", "focus_distance"});
    if (j.contains("position")) c.position = vec3(j["position"], p + "/position");
    if (j.contains("look_at")) c.look_at = vec3(j["look_at"], p + "/look_at");
    if (j.contains("up")) c.up = direction(j["up"], p + "/up");
    if (j.contains("fov")) {
      c.fov_degrees = number(j["fov"], p + "/fov");
      if (!(c.fov_degrees > 0 && c.fov_degrees < 180))
        fail(p + "/fov", "must be in (0, 180) degrees, got " + format_number(c.fov_degrees));
    }
    if (j.contains("roll")) c.roll_degrees = number(j["roll"], p + "/roll");
    if (j.contains("aperture")) c.aperture = non_negative(j["aperture"], p + "/aperture");
    if (j.contains("focus_distance"))
      c.focus_distance = positive(j["focus_distance"], p + "/focus_distance");
    glm::dvec3 fwd = c.look_at - c.position;
    if (glm::length(fwd) == 0) fail(p + "/look_at", "must differ from the camera position");
    if (glm::length(glm::cross(glm::normalize(fwd), glm::normalize(c.up))) < 1e-9)
      fail(p + "/up", "must not be parallel to the viewing direction");
  }

  void parse_film(const json& j, const std::string& p, Film& f) {
    check_keys(j, p, {"width", "height", "filter", "transfer", "gamma", "exposure", "tonemap"});
    if (j.contains("width")) f.width = static_cast<int>(integer(j["width"], p + "/width", 1, 16384));
    if (j.contains("height"))
      f.height = static_cast<int>(integer(j["height"], p + "/height", 1, 16384));
    if (j.contains("filter")) {
      const json& fj = j["filter"];
      std::string fp = p + "/filter";
      check_keys(fj, fp, {"type", "radius"});
      std::string t = choice(require(fj, fp, "type"), fp + "/type", {"box", "tent", "gaussian"});
      f.filter.type = t == "box" ? FilterType::Box
                                 : (t == "tent" ? FilterType::Tent : FilterType::Gaussian);
      f.filter.radius = f.filter.type == FilterType::Box ? 0.5 : 1.5;
      if (fj.contains("radius")) {
        f.filter.radius = positive(fj["radius"], fp + "/radius");
        if (f.filter.radius > 8) fail(fp + "/radius", "must be <= 8 pixels");
      }
    }
    if (j.contains("transfer")) {
      std::string t = choice(j["transfer"], p + "/transfer", {"srgb", "gamma", "linear"});
      f.transfer = t == "srgb" ? Transfer::Srgb : (t == "gamma" ? Transfer::Gamma : Transfer::Linear);
    }
    if (j.contains("gamma")) f.gamma = positive(j["gamma"], p + "/gamma");
    if (j.contains("exposure")) f.exposure = number(j["exposure"], p + "/exposure");
    if (j.contains("tonemap")) {
      std::string t = choice(j["tonemap"], p + "/tonemap", {"clamp", "reinhard", "aces"});
      f.tonemap = t == "clamp" ? ToneMap::Clamp : (t == "reinhard" ? ToneMap::Reinhard : ToneMap::Aces);
    }
  }

  void parse_integrator(const json& j, const std::string& p, Integrator& in) {
    check_keys(j, p, {"type", "max_depth", "rr_depth", "spp", "seed", "ao_distance", "mis"});
    if (j.contains("type")) {
      std::string t = choice(j["type"], p + "/type",
                             {"path", "whitted", "direct", "albedo", "normal", "depth", "ao", "primitive"});
      in.type = parse_integrator_type(t);
    }
    if (j.contains("max_depth"))
      in.max_depth = static_cast<int>(integer(j["max_depth"], p + "/max_depth", 1, 100000));
    if (j.contains("rr_depth"))
      in.rr_depth = static_cast<int>(integer(j["rr_depth"], p + "/rr_depth", 1, 100000));
    if (j.contains("spp")) in.spp = static_cast<int>(integer(j["spp"], p + "/spp", 1, 1 << 24));
    if (j.contains("seed"))
      in.seed = static_cast<std::uint32_t>(integer(j["seed"], p + "/seed", 0, 0xffffffffL));
    if (j.contains("mis")) {
      if (!j["mis"].is_boolean()) fail(p + "/mis", "must be true or false, got " + type_name(j["mis"]));
      in.mis = j["mis"].get<bool>();
    }
    if (j.contains("ao_distance")) in.ao_distance = positive(j["ao_distance"], p + "/ao_distance");
  }

  static IntegratorType parse_integrator_type(const std::string& t) {
    if (t == "whitted") return IntegratorType::Whitted;
    if (t == "direct") return IntegratorType::Direct;
    if (t == "albedo") return IntegratorType::Albedo;
    if (t == "normal") return IntegratorType::Normal;
    if (t == "depth") return IntegratorType::Depth;
    if (t == "ao") return IntegratorType::Ao;
    if (t == "primitive") return IntegratorType::Primitive;
    return IntegratorType::Path;
  }

  void parse_materials(const json& j, const std::string& p, Scene& scene) {
    check_object(j, p);
    for (auto it = j.begin(); it != j.end(); ++it) {
      std::string mp = p + "/" + it.key();
      if (it.key().empty()) fail(mp, "material names must not be empty");
      scene.materials.push_back(parse_material(it.value(), mp, it.key(), scene));
    }
  }

  Material parse_material(const json& j, const std::string& p, const std::string& name,
                          Scene& scene) {
    check_object(j, p);
    Material m;
    m.name = name;
    std::string t = choice(require(j, p, "type"), p + "/type",
                           {"diffuse", "mirror", "dielectric", "conductor", "plastic"});
    if (t == "diffuse") {
      check_keys(j, p, {"type", "albedo", "emission"});
      m.type = MaterialType::Diffuse;
    } else if (t == "mirror") {
      check_keys(j, p, {"type", "reflectance", "emission"});
      m.type = MaterialType::Mirror;
      m.specular = glm::dvec3(1.0);
      if (j.contains("reflectance")) m.specular = colour(j["reflectance"], p + "/reflectance");
    } else if (t == "dielectric") {
      check_keys(j, p, {"type", "ior", "tint", "emission"});
      m.type = MaterialType::Dielectric;
      m.specular = glm::dvec3(1.0);
      if (j.contains("tint")) m.specular = colour(j["tint"], p + "/tint");
    } else if (t == "conductor") {
      check_keys(j, p, {"type", "specular", "roughness", "emission"});
      m.type = MaterialType::Conductor;
      m.specular = glm::dvec3(0.9);
      if (j.contains("specular")) m.specular = colour(j["specular"], p + "/specular");
    } else {
      check_keys(j, p, {"type", "albedo", "specular", "roughness", "ior", "emission"});
      m.type = MaterialType::Plastic;
      m.specular = glm::dvec3(1.0);
      if (j.contains("specular")) m.specular = colour(j["specular"], p + "/specular");
    }
    if (j.contains("albedo")) {
      const json& a = j["albedo"];
      if (a.is_object()) {
        check_keys(a, p + "/albedo", {"texture"});
        std::string file = string(require(a, p + "/albedo", "texture"), p + "/albedo/texture");
        try {
          m.albedo = glm::dvec3(1.0);
          m.albedo_texture = scene_detail::load_texture(scene, resolve(file));
        } catch (const Error& e) {
          fail(p + "/albedo/texture", e.what());
        }
      } else {
        m.albedo = colour(a, p + "/albedo");
      }
    }
    if (j.contains("ior")) {
      m.ior = positive(j["ior"], p + "/ior");
    }
    if (j.contains("roughness")) {
      m.roughness = number(j["roughness"], p + "/roughness");
      if (m.roughness < 0 || m.roughness > 1)
        fail(p + "/roughness", "must be in [0, 1], got " + format_number(m.roughness));
    }
    if (j.contains("emission")) m.emission = colour(j["emission"], p + "/emission");
    return m;
  }

  int material_ref(const json& j, const std::string& p, const Scene& scene) const {
    std::string name = string(j, p);
    int idx = scene.find_material(name);
    if (idx < 0) fail(p, "unknown material '" + name + "'");
    return idx;
  }

  glm::dmat4 parse_transform(const json& j, const std::string& p) const {
    if (!j.is_array()) fail(p, "must be an array of transform steps, got " + type_name(j));
    glm::dmat4 m(1.0);
    for (size_t i = 0; i < j.size(); ++i) {
      std::string sp = p + "/" + std::to_string(i);
      const json& step = j[i];
      check_object(step, sp);
      if (step.size() != 1)
        fail(sp, "each step must hold exactly one of scale, rotate, translate, matrix");
      glm::dmat4 s(1.0);
      if (step.contains("scale")) {
        const json& v = step["scale"];
        glm::dvec3 k = v.is_array() ? vec3(v, sp + "/scale") : glm::dvec3(number(v, sp + "/scale"));
        for (int a = 0; a < 3; ++a)
          if (k[a] == 0) fail(sp + "/scale", "must not be zero");
        s = glm::scale(glm::dmat4(1.0), k);
      } else if (step.contains("rotate")) {
        const json& r = step["rotate"];
        check_keys(r, sp + "/rotate", {"axis", "degrees"});
        glm::dvec3 axis = direction(require(r, sp + "/rotate", "axis"), sp + "/rotate/axis");
        double deg = number(require(r, sp + "/rotate", "degrees"), sp + "/rotate/degrees");
        s = glm::rotate(glm::dmat4(1.0), glm::radians(deg), glm::normalize(axis));
      } else if (step.contains("translate")) {
        s = glm::translate(glm::dmat4(1.0), vec3(step["translate"], sp + "/translate"));
      } else if (step.contains("matrix")) {
        const json& mj = step["matrix"];
        std::string mp = sp + "/matrix";
        if (!mj.is_array() || mj.size() != 4) fail(mp, "must be 4 rows of 4 numbers");
        for (int r = 0; r < 4; ++r) {
          const json& row = mj[r];
          std::string rp = mp + "/" + std::to_string(r);
          if (!row.is_array() || row.size() != 4) fail(rp, "must be a row of 4 numbers");
          for (int c = 0; c < 4; ++c) s[c][r] = number(row[c], rp + "/" + std::to_string(c));
        }
        if (s[0][3] != 0 || s[1][3] != 0 || s[2][3] != 0 || s[3][3] != 1)
          fail(mp, "the last row must be [0, 0, 0, 1] (affine transforms only)");
        if (std::abs(glm::determinant(s)) < 1e-300) fail(mp, "must be invertible");
      } else {
        fail(sp + "/" + step.begin().key(), "unknown transform step (allowed: scale, rotate, translate, matrix)");
      }
      m = s * m;  // steps apply in order
    }
    return m;
  }

  void parse_shape(const json& j, const std::string& p, Scene& scene) {
    check_object(j, p);
    std::string t = choice(require(j, p, "type"), p + "/type", {"sphere", "mesh", "triangles"});
    if (t == "sphere") {
      check_keys(j, p, {"type", "center", "radius", "material"});
      Sphere s;
      s.center = vec3(require(j, p, "center"), p + "/center");
      s.radius = positive(require(j, p, "radius"), p + "/radius");
      s.material = material_ref(require(j, p, "material"), p + "/material", scene);
      scene.spheres.push_back(s);
    } else if (t == "mesh") {
      check_keys(j, p, {"type", "file", "material", "transform"});
      std::string file = resolve(string(require(j, p, "file"), p + "/file"));
      int mat = j.contains("material") ? material_ref(j["material"], p + "/material", scene) : -1;
      glm::dmat4 xf = j.contains("transform") ? parse_transform(j["transform"], p + "/transform")
                                              : glm::dmat4(1.0);
      try {
        scene_detail::load_obj(scene, file, xf, mat);
      } catch (const Error& e) {
        fail(p + "/file", e.what());  // "<scene>: /shapes/2/file: <obj>:<line>: ..."
      }
    } else {
      check_keys(j, p, {"type", "positions", "indices", "normals", "uvs", "material", "transform"});
      parse_triangles(j, p, scene);
    }
  }

  void parse_triangles(const json& j, const std::string& p, Scene& scene) {
    int mat = material_ref(require(j, p, "material"), p + "/material", scene);
    glm::dmat4 xf = j.contains("transform") ? parse_transform(j["transform"], p + "/transform")
                                            : glm::dmat4(1.0);
    const json& pos = require(j, p, "positions");
    if (!pos.is_array() || pos.empty()) fail(p + "/positions", "must be a non-empty array of [x, y, z]");
    const json& idx = require(j, p, "indices");
    if (!idx.is_array() || idx.size() % 3 != 0)
      fail(p + "/indices", "must be an array whose length is a multiple of 3");
    size_t n = pos.size();
    auto read_opt = [&](const char* key, int dims) {
      std::vector<glm::dvec3> out;
      if (!j.contains(key)) return out;
      const json& a = j[key];
      std::string ap = p + "/" + key;
      if (!a.is_array() || a.size() != n)
        fail(ap, "must have one entry per position (" + std::to_string(n) + ")");
      for (size_t i = 0; i < n; ++i) {
        std::string ep = ap + "/" + std::to_string(i);
        if (dims == 3) {
          out.push_back(vec3(a[i], ep));
        } else {
          if (!a[i].is_array() || a[i].size() != 2) fail(ep, "must be an array of 2 numbers");
          out.push_back({number(a[i][0], ep + "/0"), number(a[i][1], ep + "/1"), 0});
        }
      }
      return out;
    };
    std::vector<glm::dvec3> normals = read_opt("normals", 3);
    std::vector<glm::dvec3> uvs = read_opt("uvs", 2);
    glm::dmat3 nxf = glm::transpose(glm::inverse(glm::dmat3(xf)));
    bool mirrored = glm::determinant(glm::dmat3(xf)) < 0;
    int base = static_cast<int>(scene.positions.size());
    int nbase = static_cast<int>(scene.normals.size());
    int uvbase = static_cast<int>(scene.uvs.size());
    for (size_t i = 0; i < n; ++i) {
      glm::dvec3 v = vec3(pos[i], p + "/positions/" + std::to_string(i));
      glm::dvec3 w = glm::dvec3(xf * glm::dvec4(v, 1.0));
      if (!(std::abs(w.x) <= FLT_MAX && std::abs(w.y) <= FLT_MAX && std::abs(w.z) <= FLT_MAX))
        fail(p + "/positions/" + std::to_string(i), "the transform takes it beyond float range");
      scene.positions.push_back(w);
    }
    for (auto& nn : normals) {
      glm::dvec3 t = nxf * nn;
      double len = glm::length(t);
      scene.normals.push_back(len > 0 ? t / len : t);
    }
    for (auto& uv : uvs) scene.uvs.push_back({uv.x, uv.y});
    for (size_t i = 0; i < idx.size(); i += 3) {
      Triangle tri;
      tri.material = mat;
      for (int k = 0; k < 3; ++k) {
        long v = integer(idx[i + k], p + "/indices/" + std::to_string(i + k), 0,
                         static_cast<long>(n) - 1);
        tri.v[k] = base + static_cast<int>(v);
        tri.n[k] = normals.empty() ? -1 : nbase + static_cast<int>(v);
        tri.uv[k] = uvs.empty() ? -1 : uvbase + static_cast<int>(v);
      }
      if (mirrored) {
        std::swap(tri.v[1], tri.v[2]);
        std::swap(tri.n[1], tri.n[2]);
        std::swap(tri.uv[1], tri.uv[2]);
      }
      scene.triangles.push_back(tri);
    }
  }

  void parse_light(const json& j, const std::string& p, Scene& scene) {
    check_object(j, p);
    std::string t = choice(require(j, p, "type"), p + "/type", {"point", "environment"});
    Light l;
    if (t == "point") {
      check_keys(j, p, {"type", "position", "intensity"});
      l.type = LightType::Point;
      l.position = vec3(require(j, p, "position"), p + "/position");
      l.intensity = colour(require(j, p, "intensity"), p + "/intensity");
    } else {
      check_keys(j, p, {"type", "radiance", "file", "scale"});
      if (j.contains("file")) {
        if (j.contains("radiance")) fail(p + "/radiance", "give either radiance or file, not both");
        l.type = LightType::EnvironmentMap;
        l.radiance = glm::dvec3(1.0);
        if (j.contains("scale")) l.radiance = glm::dvec3(non_negative(j["scale"], p + "/scale"));
        try {
          l.texture = scene_detail::load_texture(scene, resolve(string(j["file"], p + "/file")));
        } catch (const Error& e) {
          fail(p + "/file", e.what());
        }
      } else {
        if (j.contains("scale")) fail(p + "/scale", "only allowed with file");
        l.type = LightType::Environment;
        l.radiance = colour(require(j, p, "radiance"), p + "/radiance");
      }
      for (auto& other : scene.lights)
        if (other.type != LightType::Point) fail(p, "only one environment light is allowed");
    }
    scene.lights.push_back(l);
  }

 private:
  std::string file_;
  fs::path dir_;
};

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

}  // namespace

Scene parse_scene(const std::string& text, const std::string& path) {
  scene_detail::check_json_structure(text, path);  // nesting depth, duplicate keys
  json root;
  try {
    root = json::parse(text);
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
  Scene scene;
  scene.path = path;
  Parser parser(path, fs::path(path).parent_path());
  parser.parse(root, scene);
  return scene;
}

Scene load_scene(const std::string& path) {
  return parse_scene(scene_detail::read_scene_text(path), path);  // bounded; pipes allowed
}

}  // namespace lucent
