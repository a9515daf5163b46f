#include "fuzz_common.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "scene/loaders.hpp"

namespace lucent::fuzz {

namespace fs = std::filesystem;

namespace {

const char kMarker[] = "\n@@ ";

bool good_name(const std::string& n) {
  if (n.empty() || n.size() > 32 || n[0] == '.') return false;
  for (char c : n)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-'))
      return false;
  return true;
}

std::vector<std::string>& written() {
  static std::vector<std::string> files;
  return files;
}

void ignore(const std::string&) {}

bool finite_float(double v) { return std::isfinite(v) && std::abs(v) <= FLT_MAX; }
bool finite3(const glm::dvec3& v) {
  return finite_float(v.x) && finite_float(v.y) && finite_float(v.z);
}

}  // namespace

Bundle parse_bundle(const std::uint8_t* data, std::size_t size) {
  const std::string in(reinterpret_cast<const char*>(data), size);
  Bundle b;
  std::size_t at = in.find(kMarker);
  b.main = in.substr(0, at);
  while (at != std::string::npos) {
    std::size_t name_start = at + sizeof kMarker - 1;
    std::size_t eol = in.find('\n', name_start);
    if (eol == std::string::npos) break;
    std::string name = in.substr(name_start, eol - name_start);
    at = in.find(kMarker, eol);
    std::string body = in.substr(eol + 1, at == std::string::npos ? at : at - eol - 1);
    if (good_name(name)) b.parts.emplace_back(std::move(name), std::move(body));
  }
  return b;
}

std::string make_bundle(const std::string& main,
                        const std::vector<std::pair<std::string, std::string>>& parts) {
  std::string out = main;
  for (const auto& [name, body] : parts) out += kMarker + name + "\n" + body;
  return out;
}

std::string write_bundle(const Bundle& b, const std::string& main_name) {
  static const std::string dir = [] {
    std::string base =
        fs::is_directory("/dev/shm") ? "/dev/shm" : fs::temp_directory_path().string();
    std::string d = base + "/lucent-fuzz-" + std::to_string(::getpid());
    fs::create_directories(d);
    return d;
  }();
  for (const std::string& f : written()) ::unlink(f.c_str());
  written().clear();
  auto put = [&](const std::string& name, const std::string& body) {
    std::string path = dir + "/" + name;
    std::ofstream(path, std::ios::binary | std::ios::trunc) << body;
    written().push_back(path);
  };
  put(main_name, b.main);
  for (const auto& [name, body] : b.parts)
    if (name != main_name) put(name, body);
  return dir;
}

void silence_warnings() { scene_detail::set_warning_sink(ignore); }

void check_scene(const Scene& s) {
  const int nm = static_cast<int>(s.materials.size());
  const int nt = static_cast<int>(s.textures.size());
  const auto np = s.positions.size(), nn = s.normals.size(), nuv = s.uvs.size();
  for (const glm::dvec3& p : s.positions) check(finite3(p), "a position is not a finite float");
  for (const glm::dvec3& n : s.normals) check(finite3(n), "a normal is not finite");
  for (const glm::dvec2& uv : s.uvs)
    check(finite_float(uv.x) && finite_float(uv.y), "a uv is not a finite float");
  for (const Triangle& t : s.triangles) {
    check(t.material >= 0 && t.material < nm, "triangle material out of range");
    for (int k = 0; k < 3; ++k) {
      check(t.v[k] >= 0 && static_cast<size_t>(t.v[k]) < np, "triangle vertex out of range");
      check(t.n[k] >= -1 && (t.n[k] < 0 || static_cast<size_t>(t.n[k]) < nn),
            "triangle normal out of range");
      check(t.uv[k] >= -1 && (t.uv[k] < 0 || static_cast<size_t>(t.uv[k]) < nuv),
            "triangle uv out of range");
    }
  }
  for (const Sphere& sp : s.spheres) {
    check(sp.material >= 0 && sp.material < nm, "sphere material out of range");
    check(finite3(sp.center) && finite_float(sp.radius) && sp.radius > 0, "bad sphere");
  }
  for (const Material& m : s.materials) {
    check(finite3(m.albedo) && finite3(m.emission) && finite3(m.specular), "material colour");
    check(finite_float(m.ior) && finite_float(m.roughness), "material ior or roughness");
    check(m.albedo_texture >= -1 && m.albedo_texture < nt, "material texture out of range");
  }
  for (const Light& l : s.lights) {
    check(finite3(l.position) && finite3(l.intensity) && finite3(l.radiance), "light values");
    check(l.texture >= -1 && l.texture < nt, "light texture out of range");
  }
  for (const Texture& t : s.textures) {
    check(t.width > 0 && t.height > 0, "empty texture");
    check(t.rgba.size() == static_cast<size_t>(t.width) * t.height * 4, "texture size");
  }
  const Camera& c = s.camera;
  check(finite3(c.position) && finite3(c.look_at) && finite3(c.up), "camera vectors");
  check(finite_float(c.fov_degrees) && finite_float(c.aperture) && finite_float(c.focus_distance),
        "camera numbers");
  check(s.film.width >= 1 && s.film.height >= 1, "film size");
}

}  // namespace lucent::fuzz
