#include "support.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "cl/kernel_source.hpp"
#include "cl/program_cache.hpp"
#include "lucent/compare.hpp"
#include "lucent/session.hpp"
#include "scene/loaders.hpp"

namespace lucent::test {

namespace fs = std::filesystem;

namespace {
std::string read_all(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

struct TempRoot {
  std::string path;
  TempRoot() {
    path = std::string(LUCENT_BINARY_DIR) + "/test_tmp/" + std::to_string(::getpid());
    // a killed test process of the same pid left its directory (pids are reused): a test then
    // found the files of another one's run in its own (a converge output "already written")
    std::error_code ec;
    fs::remove_all(path, ec);
    fs::create_directories(path);
  }
  ~TempRoot() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

TempRoot& temp_root() {
  static TempRoot root;
  return root;
}
}  // namespace

SessionOptions session_options() { return SessionOptions::from_environment(); }
std::string device() { return session_options().device; }
std::string kernel_dir() { return session_options().kernel_dir; }
std::string cache_dir() {
  std::string dir = session_options().cache_dir;
  if (dir == "off") return "";
  return dir.empty() ? cl_util::default_program_cache_dir() : dir;
}

RenderOptions render_options() {
  SessionOptions env = session_options();
  RenderOptions o;
  o.device = env.device;
  o.kernel_dir = env.kernel_dir;
  o.cache_dir = env.cache_dir;
  return o;
}

RenderResult render(const Scene& scene, RenderOptions options) {
  SessionOptions env = session_options();
  if (options.device.empty()) options.device = env.device;
  if (options.kernel_dir.empty()) options.kernel_dir = env.kernel_dir;
  if (options.cache_dir.empty()) options.cache_dir = env.cache_dir;
  return lucent::render(scene, options);
}

std::string kernel_copy() {
  std::string dir = temp_dir() + "/kernels";
  for (int i = 0; i < lucent::detail::kEmbeddedKernelFileCount; ++i) {
    const auto& f = lucent::detail::kEmbeddedKernelFiles[i];
    std::filesystem::path p = std::filesystem::path(dir) / f.path;
    std::filesystem::create_directories(p.parent_path());
    write_file(p.string(), f.content);
  }
  return dir;
}

std::string temp_dir() {
  static std::atomic<int> counter{0};
  std::string dir = temp_root().path + "/" + std::to_string(counter++);
  fs::create_directories(dir);
  return dir;
}

CommandResult run_cli(const std::string& args, const std::string& env) {
  std::string dir = temp_dir();
  std::string out = dir + "/stdout", err = dir + "/stderr";
  std::string cmd = (env.empty() ? "" : env + " ") + std::string("'") + LUCENT_CLI_PATH + "' " +
                    args + " </dev/null >'" + out + "' 2>'" + err + "'";
  int raw = std::system(cmd.c_str());
  CommandResult r;
  if (WIFEXITED(raw))
    r.status = WEXITSTATUS(raw);
  else if (WIFSIGNALED(raw))
    r.status = 128 + WTERMSIG(raw);
  r.out = read_all(out);
  r.err = read_all(err);
  return r;
}

void write_file(const std::string& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary);
  f << text;
}

std::string read_file(const std::string& path) { return read_all(path); }

std::uint32_t crc32(const std::string& data) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (unsigned char b : data) {
    c ^= b;
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
  }
  return ~c;
}

namespace {

std::string be32(std::uint32_t v) { return {char(v >> 24), char(v >> 16), char(v >> 8), char(v)}; }

}  // namespace

std::string png_file(int width, int height, int bit_depth, int colour_type,
                     const std::vector<std::pair<std::string, std::string>>& chunks,
                     const std::string& rows) {
  if (rows.size() >= 65536) throw std::runtime_error("png_file: rows must fit one stored block");
  std::uint32_t a = 1, b = 0;
  for (unsigned char c : rows) {
    a = (a + c) % 65521;
    b = (b + a) % 65521;
  }
  const std::uint16_t len = static_cast<std::uint16_t>(rows.size()),
                      nlen = static_cast<std::uint16_t>(~len);
  std::string z = "\x78\x01";
  z += '\x01';  // final stored block
  z += {char(len & 0xFF), char(len >> 8), char(nlen & 0xFF), char(nlen >> 8)};
  z += rows + be32((b << 16) | a);
  auto chunk = [](const std::string& tag, const std::string& data) {
    return be32(static_cast<std::uint32_t>(data.size())) + tag + data + be32(crc32(tag + data));
  };
  std::string ihdr = be32(static_cast<std::uint32_t>(width)) +
                     be32(static_cast<std::uint32_t>(height)) + char(bit_depth) +
                     char(colour_type) + std::string(3, '\0');
  std::string png = std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr);
  for (const auto& [tag, data] : chunks) png += chunk(tag, data);
  return png + chunk("IDAT", z) + chunk("IEND", "");
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const lucent::Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("unexpected exception type: ") + e.what();
  }
  return "";
}

ScopedEnv::ScopedEnv(const char* name, const char* value) : name_(name) {
  if (const char* old = std::getenv(name)) {
    had_ = true;
    old_ = old;
  }
  if (value)
    ::setenv(name, value, 1);
  else
    ::unsetenv(name);
}

ScopedEnv::~ScopedEnv() {
  if (had_)
    ::setenv(name_.c_str(), old_.c_str(), 1);
  else
    ::unsetenv(name_.c_str());
}

std::string source_path(const std::string& rel) {
  return std::string(LUCENT_SOURCE_DIR) + "/" + rel;
}

std::string shared_asset(const std::string& rel) {
  std::string p = std::string(LUCENT_SHARED_DIR) + "/assets/" + rel;
  return fs::exists(p) ? p : std::string();
}

Scene with_independent_samples(Scene scene) {
  scene.integrator.sampler = SamplerType::Independent;
  return scene;
}

Scene scene_from(const std::string& json) {
  Scene scene = parse_scene(json, temp_dir() + "/scene.json");
  return json.find("\"sampler\"") != std::string::npos ? scene : with_independent_samples(scene);
}

RenderResult render_json(const std::string& json, int spp, bool specialize) {
  Scene scene = scene_from(json);
  RenderOptions opt;
  opt.spp = spp;
  opt.specialize = specialize;
  return lucent::test::render(scene, opt);
}

int count_lines(const std::string& s) {
  std::istringstream in(s);
  std::string line;
  int n = 0;
  while (std::getline(in, line))
    if (!line.empty()) ++n;
  return n;
}

namespace {
std::vector<std::string>& captured_warnings() {
  static std::vector<std::string> v;
  return v;
}
}  // namespace

CaptureWarnings::CaptureWarnings() {
  captured_warnings().clear();
  scene_detail::set_warning_sink([](const std::string& m) { captured_warnings().push_back(m); });
}
CaptureWarnings::~CaptureWarnings() { scene_detail::set_warning_sink(nullptr); }
const std::vector<std::string>& CaptureWarnings::all() const { return captured_warnings(); }
int CaptureWarnings::count(const std::string& needle) const {
  int n = 0;
  for (const auto& w : all()) n += w.find(needle) != std::string::npos;
  return n;
}
std::string CaptureWarnings::dump() const {
  std::string s;
  for (const auto& w : all()) s += "  " + w + "\n";
  return s;
}

double sidak_z(double alpha, int m) {
  // per-test level 1 - (1 - alpha)^(1/m), computed without cancellation
  return normal_two_sided_critical(-std::expm1(std::log1p(-alpha) / m));
}

PooledChi2 pooled_chi2(const std::vector<double>& observed, const std::vector<double>& expected,
                       double min_expected) {
  PooledChi2 r;
  for (size_t i = 0; i < expected.size(); ++i) {
    if (expected[i] < min_expected) {
      r.pooled_observed += observed[i];
      r.pooled_expected += expected[i];
      continue;
    }
    r.chi2 += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
    ++r.cells;
  }
  if (r.pooled_expected >= min_expected) {
    const double d = r.pooled_observed - r.pooled_expected;
    r.chi2 += d * d / r.pooled_expected;
    ++r.cells;
  }
  return r;
}

double chi2_pvalue(double chi2, int dof) {
  const double a = dof / 2.0, x = chi2 / 2.0;
  if (x <= 0) return 1;
  const double gln = std::lgamma(a);
  if (x < a + 1) {  // series for P, then Q = 1 - P
    double sum = 1 / a, del = sum, ap = a;
    for (int n = 0; n < 10000; ++n) {
      ap += 1;
      del *= x / ap;
      sum += del;
      if (std::abs(del) < std::abs(sum) * 1e-15) break;
    }
    return 1 - sum * std::exp(-x + a * std::log(x) - gln);
  }
  double b = x + 1 - a, c = 1e300, d = 1 / b, h = d;  // continued fraction for Q (Lentz)
  for (int i = 1; i < 10000; ++i) {
    double an = -i * (i - a);
    b += 2;
    d = an * d + b;
    if (std::abs(d) < 1e-300) d = 1e-300;
    c = b + an / c;
    if (std::abs(c) < 1e-300) c = 1e-300;
    d = 1 / d;
    double del = d * c;
    h *= del;
    if (std::abs(del - 1) < 1e-15) break;
  }
  return std::exp(-x + a * std::log(x) - gln) * h;
}

void expect_matches(const RenderResult& r, const std::function<double(int, int, int)>& expected) {
  const int w = r.mean.width, h = r.mean.height;
  const double zmax = sidak_z(1e-3, w * h * 3);
  int failures = 0;
  double worst = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        double e = expected(x, y, c);
        double n = r.samples[static_cast<size_t>(y) * w + x];
        double se = std::sqrt(r.variance.pixel(x, y)[c] / n) + 1e-6 + 1e-4 * std::abs(e);
        double z = std::abs(r.mean.pixel(x, y)[c] - e) / se;
        worst = std::max(worst, z);
        if (!(z <= zmax) && ++failures <= 5)  // NaN fails too
          ADD_FAILURE() << "pixel (" << x << "," << y << ") channel " << c << ": "
                        << r.mean.pixel(x, y)[c] << " vs expected " << e << " (z = " << z << ")";
      }
  EXPECT_EQ(failures, 0) << "worst z " << worst << ", threshold " << zmax;
  EXPECT_EQ(r.nonfinite, 0u);
}

std::map<std::string, std::string> parse_report(const std::string& out) {
  std::map<std::string, std::string> m;
  std::istringstream in(out);
  std::string section;
  for (std::string line; std::getline(in, line);) {
    if (line.empty()) continue;
    bool indented = line[0] == ' ';
    // key and value are separated by two or more spaces
    size_t start = line.find_first_not_of(' ');
    size_t gap = line.find("  ", start);
    std::string key =
        line.substr(start, gap == std::string::npos ? std::string::npos : gap - start);
    std::string value;
    if (gap != std::string::npos) value = line.substr(line.find_first_not_of(' ', gap));
    if (!indented) section = key;
    m[indented ? section + "/" + key : key] = value;
  }
  return m;
}

std::string bounced_caustic_scene(bool caustics, int max_depth, const std::string& light,
                                  const std::string& more, const std::string& camera) {
  return R"({
    "camera": )" +
         camera + R"(,
    "film": {"width": 16, "height": 12},
    "integrator": {"type": "path", "max_depth": )" +
         std::to_string(max_depth) + R"(, "caustics": )" + (caustics ? "true" : "false") + R"(},
    "materials": {"white": {"type": "diffuse", "albedo": [0.8, 0.8, 0.8]},
                  "black": {"type": "diffuse", "albedo": [0, 0, 0]},
                  "mirror": {"type": "mirror", "reflectance": [1, 1, 1]},
                  "frosted": {"type": "rough_dielectric", "ior": 1.5, "roughness": 0.3},
                  "lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [4, 4, 4]}},
    "shapes": [{"type": "triangles", "material": "white",
                "positions": [[-6,-6,0],[6,-6,0],[6,6,0],[-6,6,0]],
                "indices": [0,1,2, 0,2,3]},
               {"type": "triangles", "material": "white",
                "positions": [[-1.5,-1.5,1.9],[1.5,-1.5,1.9],[1.5,1.5,1.9],[-1.5,1.5,1.9]],
                "indices": [0,2,1, 0,3,2]},
               {"type": "triangles", "material": "black",
                "positions": [[-1.5,-1.5,1.95],[1.5,-1.5,1.95],[1.5,1.5,1.95],[-1.5,1.5,1.95]],
                "indices": [0,1,2, 0,2,3]},
               {"type": "triangles", "material": "mirror",
                "positions": [[-3,-3,3.2],[3,-3,3.2],[3,3,3.2],[-3,3,3.2]],
                "indices": [0,2,1, 0,3,2]})" +
         more + light + "}";
}

std::string glass_lamp_box_scene(int width, int height, const std::string& filter, int max_depth) {
  return R"({
    "camera": {"position": [0, 1, 3.5], "look_at": [0, 1, 0], "up": [0, 1, 0], "fov": 40},
    "film": {"width": )" +
         std::to_string(width) + R"(, "height": )" + std::to_string(height) + R"(, "filter": )" +
         filter + R"(},
    "integrator": {"type": "path", "max_depth": )" +
         std::to_string(max_depth) + R"(, "caustics": true, "sampler": "independent"},
    "materials": {"wall": {"type": "diffuse", "albedo": [0.8, 0.8, 0.8]},
                  "glass": {"type": "dielectric", "ior": 1.5}},
    "shapes": [
      {"type": "triangles", "material": "wall", "indices": [0,2,1, 0,3,2],
       "positions": [[-1,0,-1],[1,0,-1],[1,0,1],[-1,0,1]]},
      {"type": "triangles", "material": "wall", "indices": [0,1,2, 0,2,3],
       "positions": [[-1,0,-1],[1,0,-1],[1,2,-1],[-1,2,-1]]},
      {"type": "triangles", "material": "wall", "indices": [0,1,2, 0,2,3],
       "positions": [[-1,0,-1],[-1,0,1],[-1,2,1],[-1,2,-1]]},
      {"type": "triangles", "material": "wall", "indices": [0,2,1, 0,3,2],
       "positions": [[1,0,-1],[1,0,1],[1,2,1],[1,2,-1]]},
      {"type": "sphere", "center": [0, 1, 0], "radius": 0.4, "material": "glass"}],
    "lights": [{"type": "point", "position": [0, 1, 0], "intensity": [5, 5, 5]}]
  })";
}

double ensemble_variance_ratio(const std::function<RenderResult(int)>& render, int R, int channel) {
  std::vector<std::vector<double>> means;
  std::vector<double> reported;
  for (int k = 0; k < R; ++k) {
    const RenderResult r = render(k);
    const size_t npix = r.samples.size();
    if (means.empty()) {
      means.assign(npix, {});
      reported.assign(npix, 0.0);
    }
    for (size_t i = 0; i < npix; ++i) {
      means[i].push_back(r.mean.rgb[i * 3 + channel]);
      reported[i] += r.samples[i] ? r.variance.rgb[i * 3 + channel] / r.samples[i] / R : 0.0;
    }
  }
  double emp = 0, rep = 0;
  for (size_t i = 0; i < means.size(); ++i) {
    double m = 0, m2 = 0;
    for (double v : means[i]) m += v / R;
    for (double v : means[i]) m2 += (v - m) * (v - m);
    emp += m2 / (R - 1);
    rep += reported[i];
  }
  return emp / rep;
}

double mean_image_mean_z2(const std::function<RenderResult(int)>& render, int pairs, int channel) {
  double sum = 0;
  for (int k = 0; k < pairs; ++k) {
    const double z = compare_images(render(2 * k), render(2 * k + 1)).mean_z[channel];
    sum += z * z;
  }
  return sum / pairs;
}

namespace {

/// A field of /proc/self/status, in KiB ("VmRSS:"), or -1.
long status_kib(const char* key) {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind(key, 0) == 0) return std::atol(line.c_str() + std::string(key).size());
  return -1;
}

}  // namespace

double child_peak_bytes(const std::function<bool()>& work) {
  int fds[2];
  if (::pipe(fds) != 0) return -1;
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    return -1;
  }
  if (pid == 0) {
    ::close(fds[0]);
    double added = -1;
    if (std::ofstream("/proc/self/clear_refs") << "5") {
      const long before = status_kib("VmRSS:");
      try {
        if (work()) added = 1024.0 * double(status_kib("VmHWM:") - before);
      } catch (...) {
      }
    }
    const ssize_t w = ::write(fds[1], &added, sizeof added);
    ::_exit(w == sizeof added ? 0 : 1);
  }
  ::close(fds[1]);
  double added = -1;
  if (::read(fds[0], &added, sizeof added) != sizeof added) added = -1;
  ::close(fds[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return added;
}

double cli_samples_per_second(const std::string& scene, const std::string& out) {
  const CommandResult cal = run_cli("render '" + scene + "' --time 0.5 -o '" + out + "'");
  const size_t at = cal.err.find(" Msamples/s");
  const size_t open = at == std::string::npos ? at : cal.err.rfind('(', at);
  if (cal.status != 0 || open == std::string::npos) {
    // what the render said, for the failure's report
    std::fprintf(stderr, "calibration render (status %d) said:\n%s\n", cal.status, cal.err.c_str());
    return -1;
  }
  return std::atof(cal.err.c_str() + open + 1) * 1e6;
}

std::string flat_lamp_scene(const std::string& dir) {
  const std::string path = dir + "/flat.json";
  write_file(path, R"({
    "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 30},
    "film": {"width": 500, "height": 400},
    "integrator": {"type": "path", "spp": 4, "seed": 3},
    "materials": {"lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [1, 0.5, 0.25]}},
    "shapes": [{"type": "triangles", "material": "lamp",
                "positions": [[-10,-10,0],[0.3,-10,0],[0.9,10,0],[-10,10,0]], "indices": [0,1,2, 0,2,3]}]
  })");
  return path;
}

std::string soup_obj_text(int n) {
  std::string obj;
  obj.reserve(size_t(n) * 110);
  std::uint32_t state = 12345;
  auto next = [&state] {
    state = state * 1664525u + 1013904223u;
    return double(state >> 8) / double(1 << 24) * 10.0;
  };
  char line[128];
  for (int i = 0; i < n; ++i) {
    const double x = next(), y = next(), z = next();
    std::snprintf(line, sizeof line, "v %.5f %.5f %.5f\nv %.5f %.5f %.5f\nv %.5f %.5f %.5f\n", x, y,
                  z, x + 0.01, y, z, x, y + 0.01, z);
    obj += line;
  }
  for (int i = 0; i < n; ++i) {
    std::snprintf(line, sizeof line, "f %d %d %d\n", 3 * i + 1, 3 * i + 2, 3 * i + 3);
    obj += line;
  }
  return obj;
}

}  // namespace lucent::test
