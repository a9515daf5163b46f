#include "fuzz_common.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <system_error>

#include "image/image_probe.hpp"
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
  // a directory of this process's own (mkdtemp: a stale one of a process with the same pid held
  // another run's files, which an input naming a file it did not carry then loaded), removed
  // when the process ends (one a process was left, 160 of them, one per test run)
  struct Dir {
    std::string path;
    Dir() {
      const std::string base =
          fs::is_directory("/dev/shm") ? "/dev/shm" : fs::temp_directory_path().string();
      std::string pattern = base + "/lucent-fuzz-XXXXXX";
      if (::mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp " + pattern);
      path = pattern;
    }
    ~Dir() {
      std::error_code ec;
      fs::remove_all(path, ec);
    }
  };
  static const Dir bundle_dir;
  const std::string& dir = bundle_dir.path;
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

std::string exr_file(int w, int h, const std::vector<std::string>& names,
                     const std::function<float(int, int, int)>& value, ExrLayout layout) {
  const int nc = static_cast<int>(names.size()), tile = layout.tile;
  EXRHeader header;
  InitEXRHeader(&header);
  std::vector<EXRChannelInfo> channels(nc);
  for (int c = 0; c < nc; ++c) std::strncpy(channels[c].name, names[c].c_str(), 255);
  std::vector<int> types(nc, TINYEXR_PIXELTYPE_FLOAT), stored(nc, layout.pixel_type);
  header.num_channels = nc;
  header.channels = channels.data();
  header.pixel_types = types.data();
  header.requested_pixel_types = stored.data();
  header.compression_type = layout.compression;
  header.data_window.max_x = header.display_window.max_x = w - 1;  // tile counts' source
  header.data_window.max_y = header.display_window.max_y = h - 1;
  std::deque<std::vector<float>> planes;  // stable addresses
  std::deque<std::vector<unsigned char*>> pointers;
  std::deque<std::vector<EXRTile>> tiles;
  auto plane = [&](int x0, int y0, int stride, int rows, int tw, int th, float add) {
    pointers.emplace_back();
    for (int c = 0; c < nc; ++c) {
      planes.emplace_back(static_cast<size_t>(stride) * rows, 0.0f);
      for (int j = 0; j < th; ++j)
        for (int i = 0; i < tw; ++i)
          planes.back()[size_t(j) * stride + i] = value(c, x0 + i, y0 + j) + add;
      pointers.back().push_back(reinterpret_cast<unsigned char*>(planes.back().data()));
    }
    return pointers.back().data();
  };
  std::deque<EXRImage> levels(1);
  InitEXRImage(&levels[0]);
  if (tile == 0) {
    levels[0].images = plane(0, 0, w, h, w, h, 0);
  } else {
    header.tiled = 1;
    header.tile_size_x = header.tile_size_y = tile;
    header.tile_level_mode = layout.levels;
    header.tile_rounding_mode = layout.rounding;
    const bool up = layout.rounding == TINYEXR_TILE_ROUND_UP;
    auto log2 = [&](int x) {
      int y = 0;
      bool rest = false;
      for (; x > 1; x >>= 1, ++y) rest = rest || (x & 1);
      return y + (up && rest ? 1 : 0);
    };
    auto size = [&](int top, int l) {
      return std::max(1, up ? (top + (1 << l) - 1) >> l : top >> l);
    };
    const int nx = layout.levels == TINYEXR_TILE_ONE_LEVEL
                       ? 1
                       : log2(layout.levels == TINYEXR_TILE_MIPMAP_LEVELS ? std::max(w, h) : w) + 1;
    const int ny = layout.levels == TINYEXR_TILE_RIPMAP_LEVELS ? log2(h) + 1 : nx;
    std::vector<std::pair<int, int>> order;
    if (layout.levels == TINYEXR_TILE_RIPMAP_LEVELS) {
      for (int ly = 0; ly < ny; ++ly)
        for (int lx = 0; lx < nx; ++lx) order.emplace_back(lx, ly);
    } else {
      for (int l = 0; l < nx; ++l) order.emplace_back(l, l);
    }
    for (size_t k = 0; k < order.size(); ++k) {
      const auto [lx, ly] = order[k];
      const int lw = size(w, lx), lh = size(h, ly);
      if (k > 0) {
        levels.emplace_back();
        InitEXRImage(&levels.back());
        levels[k - 1].next_level = &levels.back();
      }
      EXRImage& level = levels.back();
      level.level_x = lx;
      level.level_y = ly;
      level.width = lw;
      level.height = lh;
      level.num_channels = nc;
      tiles.emplace_back();
      for (int ty = 0; ty * tile < lh; ++ty)
        for (int tx = 0; tx * tile < lw; ++tx) {
          EXRTile t{};
          t.offset_x = tx;
          t.offset_y = ty;
          t.level_x = lx;
          t.level_y = ly;
          t.width = std::min(tile, lw - tx * tile);
          t.height = std::min(tile, lh - ty * tile);
          t.images =
              plane(tx * tile, ty * tile, tile, tile, t.width, t.height, 1000.0f * (lx + ly));
          tiles.back().push_back(t);
        }
      level.tiles = tiles.back().data();
      level.num_tiles = static_cast<int>(tiles.back().size());
    }
  }
  EXRImage& image = levels[0];
  image.num_channels = nc;
  image.width = w;
  image.height = h;
  return image_detail::save_exr_to_memory("exr_file", image, header);
}

}  // namespace lucent::fuzz
