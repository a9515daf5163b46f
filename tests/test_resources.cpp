// Bounded resources (src/render/resources.cpp): the host estimate made before packing, the device
// checks made before upload, OpenCL's out-of-resources errors, and the issue's list of requests
// that must end in one line and a non-zero exit within seconds and bounded memory. The limits are
// shrunk (DeviceLimits, ScopedLimitOverride) so that small scenes stand for huge ones.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/host_blocks.hpp"
#include "core/host_memory.hpp"
#include "lucent/compare.hpp"
#include "lucent/error.hpp"
#include "lucent/parts.hpp"
#include "lucent/reference.hpp"
#include "lucent/session.hpp"
#include "render/pack.hpp"
#include "render/resources.hpp"
#include "scene/json_guard.hpp"
#include "support.hpp"

namespace test_resources {

namespace {

using lucent::Scene;
using lucent::render_detail::ClStage;
using lucent::render_detail::DeviceLimits;
using lucent::render_detail::MemoryPart;
using lucent::render_detail::ScopedLimitOverride;

std::string q(const std::string& s) { return "'" + s + "'"; }

using lucent::test::kAddressSanitizer;

/// A shell prefix limiting the address space to `kib` KiB ("" under AddressSanitizer).
std::string ulimit_v(const std::string& kib) {
  return kAddressSanitizer ? "" : "ulimit -v " + kib + ";";
}

/// A grid of n x n quads (2 n^2 triangles) and a sphere, with an n x n film.
std::string grid_scene(int n, int film) {
  std::string pos, idx;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x)
      pos += std::string(pos.empty() ? "" : ",") + "[" + std::to_string(x) + ",0," +
             std::to_string(y) + "]";
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      int a = y * (n + 1) + x, b = a + 1, c = a + n + 1, d = c + 1;
      idx += std::string(idx.empty() ? "" : ",") + std::to_string(a) + "," + std::to_string(c) +
             "," + std::to_string(b) + "," + std::to_string(b) + "," + std::to_string(c) + "," +
             std::to_string(d);
    }
  return R"({"camera": {"position": [0, 5, -5], "look_at": [0, 0, 0]},
    "film": {"width": )" +
         std::to_string(film) + R"(, "height": )" + std::to_string(film) + R"(},
    "integrator": {"type": "albedo", "spp": 1},
    "materials": {"m": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
    "shapes": [{"type": "triangles", "material": "m", "positions": [)" +
         pos + "], \"indices\": [" + idx + R"(]},
               {"type": "sphere", "center": [0, 1, 0], "radius": 0.5, "material": "m"}]})";
}

/// A w x h PFM texture (grey) in a fresh directory, and a 4x4 scene with a sphere using it.
std::string textured_scene_file(int w, int h, int film) {
  std::string dir = lucent::test::temp_dir();
  std::string pfm = "PF\n" + std::to_string(w) + " " + std::to_string(h) + "\n-1.0\n";
  std::vector<float> px(size_t(w) * h * 3, 0.5f);
  pfm.append(reinterpret_cast<const char*>(px.data()), px.size() * sizeof(float));
  lucent::test::write_file(dir + "/t.pfm", pfm);
  lucent::test::write_file(dir + "/s.json",
                           R"({"camera": {"position": [0, 0, 3], "look_at": [0, 0, 0]},
          "film": {"width": )" +
                               std::to_string(film) + R"(, "height": )" + std::to_string(film) +
                               R"(},
          "integrator": {"type": "albedo", "spp": 1},
          "materials": {"m": {"type": "diffuse", "albedo": {"texture": "t.pfm"}}},
          "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]})");
  return dir + "/s.json";
}

std::uint64_t part(const std::vector<MemoryPart>& parts, const std::string& prefix) {
  for (const MemoryPart& p : parts)
    if (p.what.rfind(prefix, 0) == 0) return p.bytes;
  ADD_FAILURE() << "no part '" << prefix << "'";
  return 0;
}

using lucent::test::error_of;

// The largest part of a huge film's host memory: the accumulation and result images (80 bytes
// per pixel). On a CPU device with fp64 the pass sums are double4 (kernels/megakernel.cl,
// LC_ACCUM_DOUBLE) and its buffers with the work list take as much (80: mapped, not copied;
// session.cpp's HostView), and the first of equal parts is named. `accum` is that part's size as
// the message writes it.
std::string film_culprit(const std::string& film, const std::string& accum) {
  return "the largest part is the accumulation and result images of the " + film + " film (" +
         accum + "): reduce the film size";
}

// The estimate made before packing covers what packing then allocates, within a small factor.
// Sizes in messages: each in the largest unit it reaches, up to EiB, so that a count just
// below the saturated one is not "17179869184.0 GiB" beside its "16.0 EiB or more".
TEST(Resources, SizesAreInTheirLargestUnit) {
  using lucent::sys::format_bytes;
  EXPECT_EQ(format_bytes(100), "100 bytes");
  EXPECT_EQ(format_bytes(std::uint64_t(3) << 29), "1.5 GiB");
  EXPECT_EQ(format_bytes(std::uint64_t(1) << 40), "1.0 TiB");
  EXPECT_EQ(format_bytes(std::uint64_t(5) << 49), "2.5 PiB");
  EXPECT_EQ(format_bytes(std::uint64_t(1) << 60), "1.0 EiB");
  EXPECT_EQ(format_bytes(~std::uint64_t(0) - 1), "16.0 EiB");
  EXPECT_EQ(format_bytes(~std::uint64_t(0)), "16.0 EiB or more");
}

/// Makes the scene's first sphere a mirror: a delta surface, which light-traced caustics need.
void with_a_mirror(Scene& s) {
  lucent::Material mirror;
  mirror.type = lucent::MaterialType::Mirror;
  mirror.name = "mirror";
  s.materials.push_back(mirror);
  s.spheres.at(0).material = static_cast<int>(s.materials.size() - 1);
}

TEST(Resources, HostEstimateCoversThePackedScene) {
  Scene s = lucent::test::scene_from(grid_scene(40, 32));
  s.textures.push_back({"t.png", 64, 32, std::vector<float>(64 * 32 * 4, 0.5f)});
  for (int i = 0; i < 5; ++i) s.lights.push_back(lucent::point_light({0, 3, double(i)}, {1, 1, 1}));
  lucent::Material lamp = s.materials[0];  // the sphere an emitter: a light of the table too
  lamp.name = "lamp";
  lamp.emission = {1, 1, 1};
  s.materials.push_back(lamp);
  s.spheres[0].material = 1;
  auto packed = lucent::render_detail::pack_scene(s);
  DeviceLimits gpu;
  gpu.device = "gpu";
  DeviceLimits cpu = gpu;
  cpu.device = "cpu";
  cpu.host_unified = true;
  auto parts = lucent::render_detail::estimate_host_memory(s, {gpu, cpu});

  const std::uint64_t tris = packed.triangles.size() * sizeof(lc_triangle) +
                             packed.tri_attrs.size() * sizeof(lc_triangle_attr);
  EXPECT_EQ(part(parts, "the 3200 triangles"), tris);
  EXPECT_EQ(part(parts, "the 1 spheres"), sizeof(lc_sphere));
  EXPECT_GE(part(parts, "the texels of the 1 textures"), 64u * 32 * sizeof(lc_float4));
  // the light table: a packed light and a CDF entry each, beside two doubles while it is made
  // (it was not counted: 2e6 point lights took 2.7 times the estimate)
  ASSERT_EQ(packed.lights.size(), 6u);
  EXPECT_EQ(part(parts, "the table of " + std::to_string(packed.lights.size()) + " lights"),
            packed.lights.size() * (sizeof(lc_light) + sizeof(float) + 2 * sizeof(double)));
  // the BVH part (build and tree) holds the tree the kernel gets, and not 10 times more
  const std::uint64_t tree =
      packed.nodes.size() * sizeof(lc_bvh_node) + packed.leaves.size() * sizeof(lc_bvh_leaf);
  const std::uint64_t bvh = part(parts, "the BVH of 3201 primitives");
  EXPECT_GE(bvh, tree);
  EXPECT_LE(bvh, 10 * tree);
  // the film: double sums and squares, counts, result images; per device the pass read-back
  // (float4 sums and squares here: fp64 is not set), for a CPU device its buffers instead (the
  // scene's, the film's with the work list; its results are mapped, not copied)
  EXPECT_EQ(part(parts, "the accumulation and result images of the 32x32 film"), 32u * 32 * 80);
  const std::uint64_t gpu_part = part(parts, "the buffers of device 'gpu'");
  EXPECT_EQ(gpu_part, 32u * 32 * 32);
  EXPECT_EQ(part(parts, "the buffers of device 'cpu'"), gpu_part + 32u * 32 * 16);
  // the CPU device's scene buffers are the packed arrays (device_scene.hpp): counted once
  for (const MemoryPart& p : parts) EXPECT_EQ(p.what.find("scene's buffers"), std::string::npos);
  for (const MemoryPart& p : parts) EXPECT_EQ(p.what.find("caustics"), std::string::npos);
  // caustics asked for in a scene without a mirror or smooth glass: the kernel renders none, and
  // nothing is counted for them (`lucent info` counted them)
  s.integrator.type = lucent::IntegratorType::Path;
  s.integrator.caustics = true;
  parts = lucent::render_detail::estimate_host_memory(s, {gpu, cpu});
  for (const MemoryPart& p : parts) EXPECT_EQ(p.what.find("caustics"), std::string::npos);
  EXPECT_EQ(part(parts, "the buffers of device 'gpu'"), gpu_part);
  // with a mirror: the light sums in doubles, and four more float4 read-back buffers per device
  // (two films each: an adaptive work list's halves), and the pass sums twice as long (the light
  // paths' totals after them)
  with_a_mirror(s);
  parts = lucent::render_detail::estimate_host_memory(s, {gpu, cpu});
  EXPECT_EQ(part(parts, "the caustics light sums of the 32x32 film"), 32u * 32 * 48);
  EXPECT_EQ(part(parts, "the buffers of device 'gpu'"), 32u * 32 * 128);
}

/// The CLI's peak host memory in MiB for `args` (its summary line), after checking it succeeded.
double peak_host_mib(const std::string& args) {
  auto r = lucent::test::run_cli(args);
  EXPECT_EQ(r.status, 0) << r.err;
  const size_t at = r.err.find("peak host memory ");
  EXPECT_NE(at, std::string::npos) << r.err;
  return at == std::string::npos ? 0.0 : std::atof(r.err.c_str() + at + 17);
}

/// The limits of the device the CLI renders on, as the session takes them (memory sizes aside).
DeviceLimits this_device() {
  const lucent::DeviceInfo info = lucent::select_device();
  DeviceLimits device;
  device.device = info.name;
  device.host_unified = info.type == "CPU";
  device.fp64 = info.fp64;
  device.light_double = info.fp64 && info.int64_atomics;
  return device;
}

// What a render really takes on the host stays within the estimate the limits are checked
// against: the CLI's peak host memory (getrusage) for a 2048x2048 film, less that of a 16x16
// film of the same scene, against the estimate's growth over those pixels plus the PFM written
// (12 bytes a pixel). On a CPU device the pass results are mapped, not copied (session.cpp's
// HostView): with fp64 sums the copies took 64 bytes a pixel more (224 against 160 counted, a
// 990 MiB growth here), which this bound refuses. Not under AddressSanitizer, whose shadow memory
// and quarantine are in the peak.
TEST(Resources, PeakHostMemoryOfALargeFilmIsWithinTheEstimate) {
  if (kAddressSanitizer) GTEST_SKIP() << "AddressSanitizer's own memory is in the peak";
  const std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/s.json", grid_scene(2, 16));
  auto peak_mib = [&](int film) {
    const std::string size = std::to_string(film);
    return peak_host_mib("render " + q(dir + "/s.json") + " -o " + q(dir + "/o.pfm") + " --width " +
                         size + " --height " + size);
  };
  peak_mib(16);  // builds the kernel (a compiler's memory is not the film's)
  const double small = peak_mib(16), large = peak_mib(2048);
  const DeviceLimits device = this_device();
  auto estimate = [&](int film) {
    Scene sc = lucent::test::scene_from(grid_scene(2, film));
    std::uint64_t bytes = 0;
    for (const MemoryPart& p : lucent::render_detail::estimate_host_memory(sc, {device}))
      bytes += p.bytes;
    return double(bytes);
  };
  const double growth = (estimate(2048) - estimate(16)) / 1048576.0;
  const double pfm = 2048.0 * 2048.0 * 12 / 1048576.0;
  EXPECT_LE(large - small, 1.1 * growth + pfm)
      << "peak " << large << " MiB against " << small << " MiB for 16x16; estimated growth "
      << growth << " MiB";
  // and the film's memory is there: the estimate is not a wide overestimate
  EXPECT_GE(large - small, 0.6 * growth) << large << " " << small << " " << growth;
}

/// A scene of `n` separate small triangles scattered in a 10-unit cube (an OBJ "soup": the BVH's
/// leaves hold one triangle each), written to dir/soup<n>.json; returns its path.
std::string soup_scene(const std::string& dir, int n) {
  const std::string obj = lucent::test::soup_obj_text(n);
  const std::string name = "soup" + std::to_string(n);
  lucent::test::write_file(dir + "/" + name + ".obj", obj);
  lucent::test::write_file(dir + "/" + name + ".json",
                           R"({"camera": {"position": [5, 5, -20], "look_at": [5, 5, 5]},
    "film": {"width": 16, "height": 16},
    "integrator": {"type": "path", "spp": 1},
    "materials": {"m": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
    "lights": [{"type": "point", "position": [5, 5, -10], "intensity": [100, 100, 100]}],
    "shapes": [{"type": "mesh", "file": ")" +
                               name + R"(.obj", "material": "m"}]})");
  return dir + "/" + name + ".json";
}

/// A scene of `n` inline positions "[0,0,0]" (the densest mesh text: 8 bytes a vertex) and one
/// triangle, rendered from afar at 16x16.
std::string dense_json(std::size_t n) {
  std::string text = R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
    "film": {"width": 16, "height": 16}, "integrator": {"type": "path", "spp": 1},
    "materials": {"m": {"type": "diffuse"}},
    "lights": [{"type": "point", "position": [0, 0, 3], "intensity": [1, 1, 1]}],
    "shapes": [{"type": "triangles", "material": "m", "indices": [0, 1, 2], "positions": [)";
  text.reserve(text.size() + 8 * n + 64);
  text += "[0,0,0],[1,0,0],[0,1,0]";
  for (std::size_t i = 3; i < n; ++i) text += ",[0,0,0]";
  return text + "]}]}";
}

// A scene's JSON text is counted before it is parsed (scene_detail::json_load_bytes): a document
// beyond the host limit is refused in one line, before its values are allocated. A 248 MB scene
// under `ulimit -v` 4 GiB (the format allows 256 MiB) ran out of memory while it loaded and ended
// in std::terminate (SIGABRT).
TEST(Resources, JsonSceneBeyondTheHostLimitIsRefusedBeforeParsing) {
  const std::string text = dense_json(100000);  // 800 KB of text, 400,000 values
  DeviceLimits lim;
  lim.host_mem = 16 << 20;
  {
    ScopedLimitOverride o(lim);
    const std::string msg = error_of([&] { lucent::parse_scene(text, "dense.json"); });
    EXPECT_EQ(msg.rfind("dense.json: loading this scene's 400", 0), 0u) << msg;
    EXPECT_NE(msg.find(" JSON values needs about "), std::string::npos) << msg;
    EXPECT_NE(msg.find("more than the limit of 16.0 MiB"), std::string::npos) << msg;
    EXPECT_NE(msg.find("reduce the scene's inline arrays"), std::string::npos) << msg;
  }
  lim.host_mem = 64 << 20;
  ScopedLimitOverride o(lim);
  EXPECT_EQ(lucent::parse_scene(text, "dense.json").positions.size(), 100000u);
}

/// This process's mapped size and resident set, in pages (/proc/self/statm); 0, 0 when unknown.
struct StatmPages {
  long size = 0, resident = 0;
};
StatmPages statm_pages() {
  StatmPages p;
  if (FILE* statm = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(statm, "%ld %ld", &p.size, &p.resident) != 2) p = {};
    std::fclose(statm);
  }
  return p;
}

/// The peak resident memory that `f` adds, in MiB, measured in a forked child (getrusage's high
/// mark against the child's resident set when it starts); -1 when the child fails.
double child_peak_growth_mib(const std::function<void()>& f) {
  int fds[2];
  if (pipe(fds) != 0) return -1;
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    const long resident = statm_pages().resident;
    double growth = -1;
    try {
      f();
      struct rusage ru;
      getrusage(RUSAGE_SELF, &ru);
      growth =
          (double(ru.ru_maxrss) * 1024.0 - double(resident) * sysconf(_SC_PAGESIZE)) / 1048576.0;
    } catch (...) {
    }
    if (write(fds[1], &growth, sizeof growth) != sizeof growth) _exit(1);
    _exit(0);
  }
  close(fds[1]);
  double growth = -1;
  if (read(fds[0], &growth, sizeof growth) != sizeof growth) growth = -1;
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  return growth;
}

// What loading an inline mesh really takes stays within that count (measured: 22-24 bytes of
// peak per byte of such text; counted 1.3-1.5 times that), and is not a wide overestimate. Not
// under AddressSanitizer, whose shadow memory and quarantine are in the peak.
TEST(Resources, PeakHostMemoryOfAnInlineMeshIsWithinTheCount) {
  if (kAddressSanitizer) GTEST_SKIP() << "AddressSanitizer's own memory is in the peak";
  const std::string text = dense_json(500000);
  std::uint64_t counted = 0;
  {
    // the count check_json_structure makes, read back from its refusal under a 1-byte limit
    DeviceLimits lim;
    lim.host_mem = 1;
    ScopedLimitOverride o(lim);
    const std::string msg = error_of([&] { lucent::parse_scene(text, "dense.json"); });
    const size_t at = msg.find("needs about ");
    ASSERT_NE(at, std::string::npos) << msg;
    counted = std::uint64_t(std::atof(msg.c_str() + at + 12) * 1048576.0);
    ASSERT_NE(msg.find(" MiB of host memory", at), std::string::npos) << msg;
  }
  // the text is the caller's before the load: the child's peak is the load's own
  const double peak = child_peak_growth_mib([&] { lucent::parse_scene(text, "dense.json"); });
  const double count = double(counted) / 1048576.0 - double(text.size()) / 1048576.0;
  EXPECT_GT(peak, 0.0);
  std::printf("inline mesh: load peak %.1f MiB, counted %.1f MiB\n", peak, count);
  EXPECT_LE(peak, count) << "peak " << peak << " MiB against a count of " << count << " MiB";
  EXPECT_GE(peak, 0.4 * count) << "peak " << peak << " MiB against a count of " << count << " MiB";
}

// release_json frees a parsed document without allocating. In a child process whose memory is
// then exhausted (an address-space limit, and every block malloc still gives taken), it returns,
// where the document's own destructor (which first moves a container's elements into a vector as
// large as the container) ends the child in std::terminate.
TEST(Resources, JsonDocumentIsFreedWithoutAllocating) {
  if (kAddressSanitizer) GTEST_SKIP() << "AddressSanitizer reserves address space: no RLIMIT_AS";
  auto child = [](bool release) {
    const pid_t pid = fork();
    if (pid == 0) {
      const struct rlimit no_core = {0, 0};
      setrlimit(RLIMIT_CORE, &no_core);
      if (FILE* null = std::freopen("/dev/null", "w", stderr)) (void)null;  // "terminate called"
      nlohmann::json doc = nlohmann::json::array();
      for (int i = 0; i < 4000000; ++i) doc.push_back(i);
      std::vector<void*> ballast;
      ballast.reserve(std::size_t(1) << 20);
      const long pages = statm_pages().size;
      if (pages <= 0) _exit(3);
      const rlim_t size = rlim_t(pages) * rlim_t(sysconf(_SC_PAGESIZE)) + (8 << 20);
      const struct rlimit rl = {size, size};
      if (setrlimit(RLIMIT_AS, &rl) != 0) _exit(4);
      // what is left, taken: new mappings up to the limit, and the heap's free blocks
      for (const std::size_t block :
           {std::size_t(1) << 20, std::size_t(1) << 16, std::size_t(1) << 12})
        while (ballast.size() < ballast.capacity()) {
          void* p = std::malloc(block);
          if (!p) break;
          ballast.push_back(p);
        }
      if (release)
        lucent::scene_detail::release_json(doc);
      else
        nlohmann::json(std::move(doc));  // the destructor (64 MB for its stack of elements)
      _exit(doc.is_null() ? 0 : 5);
    }
    int status = 0;
    waitpid(pid, &status, 0);
    return status;
  };
  const int released = child(true);
  EXPECT_TRUE(WIFEXITED(released) && WEXITSTATUS(released) == 0) << released;
  const int destroyed = child(false);
  EXPECT_TRUE(WIFSIGNALED(destroyed) && WTERMSIG(destroyed) == SIGABRT)
      << "the control: nlohmann's destructor allocates (status " << destroyed << ")";
}

// Packing outside a render (lucent info, Python's scene_info) is checked against the host limit
// first, the film left out (info allocates none): info built the BVH of 6.9M triangles past an
// address-space limit and ended in a bare "out of memory", where render refused at once (the
// BVH campaign).
TEST(Resources, PackingOutsideARenderIsCheckedAgainstTheHostLimit) {
  const Scene s = lucent::test::scene_from(grid_scene(100, 2048));
  std::uint64_t packing = 0, film = 0;
  for (const MemoryPart& p : lucent::render_detail::estimate_host_memory(s, {}, 1))
    (p.reduce.rfind("the film size", 0) == 0 ? film : packing) += p.bytes;
  ASSERT_GT(film, packing);  // a 2048x2048 film: more than the scene's packing
  DeviceLimits lim;
  lim.host_mem = packing + (1 << 20);
  {
    ScopedLimitOverride o(lim);
    EXPECT_EQ(error_of([&] { lucent::render_detail::check_packing_host_memory(s); }), "");
  }
  lim.host_mem = packing / 2;
  ScopedLimitOverride o(lim);
  const std::string msg = error_of([&] { lucent::render_detail::check_packing_host_memory(s); });
  EXPECT_NE(msg.find(": packing it (its BVH and buffers) needs about "), std::string::npos) << msg;
  EXPECT_NE(msg.find("the largest part is the BVH of 20001 primitives"), std::string::npos) << msg;
}

// Each OBJ file is bounded, and so are all of a scene's meshes together: as they load, the
// scene's arrays (as they grow) and the file being read must stay within the host limit. Twelve
// copies of a 10^6-triangle soup under `ulimit -v` 2 GB read for 14 s and ended in a bare "out
// of memory"; three copies of a 20,000-triangle soup under a 12 MiB limit: the third is refused,
// naming its place.
TEST(Resources, MeshesTogetherStayWithinTheHostLimit) {
  const std::string dir = lucent::test::temp_dir();
  soup_scene(dir, 20000);
  std::string shapes;
  for (int i = 0; i < 3; ++i)
    shapes += std::string(i ? ", " : "") +
              R"({"type": "mesh", "file": "soup20000.obj", "material": "m"})";
  lucent::test::write_file(dir + "/three.json",
                           R"({"camera": {"position": [5, 5, -20], "look_at": [5, 5, 5]},
    "materials": {"m": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
    "shapes": [)" + shapes + "]}");
  EXPECT_EQ(lucent::load_scene(dir + "/three.json").triangles.size(), 60000u);
  DeviceLimits lim;
  lim.host_mem = 12 << 20;
  ScopedLimitOverride o(lim);
  const std::string msg = error_of([&] { lucent::load_scene(dir + "/three.json"); });
  EXPECT_EQ(msg.rfind(dir + "/three.json: /shapes/2/file: ", 0), 0u) << msg;
  EXPECT_NE(msg.find("soup20000.obj: with this mesh (20000 triangles) the scene's meshes need "
                     "about "),
            std::string::npos)
      << msg;
  EXPECT_NE(msg.find("more than the limit of 12.0 MiB"), std::string::npos) << msg;
  EXPECT_NE(msg.find("reduce the meshes' size or number"), std::string::npos) << msg;
}

// The same for a mesh: a soup of 300,000 separate triangles against one of 3,000. It took 57%
// more than estimated (the resources review, at 10^6): the estimate counted a BVH leaf block per
// two primitives where a soup has one per primitive, and not the scene description that the
// application and the session each hold (nor did glibc give back the OBJ loader's freed arrays).
TEST(Resources, PeakHostMemoryOfALargeMeshIsWithinTheEstimate) {
  if (kAddressSanitizer) GTEST_SKIP() << "AddressSanitizer's own memory is in the peak";
  const std::string dir = lucent::test::temp_dir();
  auto peak_mib = [&](const std::string& scene) {
    return peak_host_mib("render " + q(scene) + " -o " + q(dir + "/o.pfm"));
  };
  const std::string small_scene = soup_scene(dir, 3000), large_scene = soup_scene(dir, 300000);
  peak_mib(small_scene);  // builds the kernel (a compiler's memory is not the mesh's)
  const double small = peak_mib(small_scene), large = peak_mib(large_scene);
  const DeviceLimits device = this_device();
  auto estimate = [&](const std::string& scene) {
    std::uint64_t bytes = 0;
    // (one description: lucent render gives its scene to the session, set_scene(Scene&&))
    for (const MemoryPart& p :
         lucent::render_detail::estimate_host_memory(lucent::load_scene(scene), {device}, 1))
      bytes += p.bytes;
    return double(bytes) / 1048576.0;
  };
  const double growth = estimate(large_scene) - estimate(small_scene);
  EXPECT_LE(large - small, 1.1 * growth) << "peak " << large << " MiB against " << small
                                         << " MiB; estimated growth " << growth << " MiB";
  // and the mesh's memory is there: the estimate is not a wide overestimate
  EXPECT_GE(large - small, 0.6 * growth) << large << " " << small << " " << growth;
}

// Over the host limit: one line naming the total, the limit, the largest part and what to reduce.
TEST(Resources, HostLimitNamesTheCulprit) {
  Scene s = lucent::test::scene_from(grid_scene(2, 4));
  s.path = "big.json";
  s.film.width = s.film.height = 16384;  // numbers only: nothing is allocated
  DeviceLimits d;
  d.device = "dev";
  std::string msg =
      error_of([&] { lucent::render_detail::check_host_memory(s, {d}, std::uint64_t(16) << 30); });
  EXPECT_EQ(msg,
            "big.json: rendering needs about 28.0 GiB of host memory, more than the limit of "
            "16.0 GiB (80% of physical memory); the largest part is the accumulation and result "
            "images of the 16384x16384 film (20.0 GiB): reduce the film size");
  // a texture whose size is all the scene asks (its pixels are not needed for the estimate)
  s.film.width = s.film.height = 4;
  s.textures.push_back({"huge.exr", 16384, 16384, {}});
  msg = error_of([&] { lucent::render_detail::check_host_memory(s, {d}, std::uint64_t(1) << 30); });
  EXPECT_NE(msg.find("more than the limit of 1.0 GiB"), std::string::npos) << msg;
  EXPECT_NE(msg.find("the largest part is the texels of the 1 textures (4.0 GiB): reduce the "
                     "textures' resolution"),
            std::string::npos)
      << msg;
  // within the limit: nothing to say; 0: no limit known
  EXPECT_EQ(
      error_of([&] { lucent::render_detail::check_host_memory(s, {d}, std::uint64_t(8) << 30); }),
      "");
  EXPECT_EQ(error_of([&] { lucent::render_detail::check_host_memory(s, {d}, 0); }), "");
}

// Byte counts saturate instead of wrapping: a film of 2147352580x536903681 pixels (2^60 + 4) was
// counted as 3783 bytes, passed the check and aborted in PoCL; 2^30 x 2^30 counted 0 bytes; and an
// application's reservation near 2^64 wrapped the total below the limit. Every film too large for
// 64 bits of bytes, alone or with the reservation, is refused by the check, as is every film in
// between (the count never falls as the film grows).
TEST(Resources, HostCountsSaturateInsteadOfWrapping) {
  Scene s = lucent::test::scene_from(grid_scene(2, 4));
  s.path = "huge.json";
  DeviceLimits cpu;
  cpu.device = "cpu";
  cpu.host_unified = true;
  const std::uint64_t limit = std::uint64_t(16) << 30;
  auto refused = [&](int w, int h, const std::vector<MemoryPart>& extra = {}) {
    s.film.width = w;
    s.film.height = h;
    return error_of(
        [&] { lucent::render_detail::check_host_memory(s, {cpu}, limit, "memory", extra); });
  };
  for (auto [w, h] : {std::pair{2147352580, 536903681}, std::pair{1073741824, 1073741824},
                      std::pair{2147483647, 2147483647}, std::pair{65536, 65536}}) {
    SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h));
    const std::string msg = refused(w, h);
    EXPECT_EQ(msg.rfind("huge.json: rendering needs about ", 0), 0u) << msg;
    EXPECT_NE(msg.find("reduce the film size"), std::string::npos) << msg;
    // a saturated count is no figure (it printed 17179869184.0 GiB)
    if (w == 2147483647) {
      EXPECT_NE(msg.find("needs about 16.0 EiB or more of host memory"), std::string::npos) << msg;
    }
    std::uint64_t largest = 0;
    for (const MemoryPart& p : lucent::render_detail::estimate_host_memory(s, {cpu}))
      largest = std::max(largest, p.bytes);
    EXPECT_GE(largest, std::uint64_t(w) * std::uint64_t(h)) << "a byte or more per pixel";
  }
  // the adaptive render's and the reference's counts, and the device buffers'
  s.film.width = 2147352580;
  s.film.height = 536903681;
  EXPECT_NE(error_of([&] {
              lucent::render_detail::check_adaptive_host_memory(s, {cpu}, true, limit, "memory",
                                                                {});
            }),
            "");
  EXPECT_GE(lucent::render_detail::adaptive_host_bytes(std::uint64_t(1) << 62, true),
            std::uint64_t(1) << 62);
  for (const MemoryPart& p :
       lucent::render_detail::film_device_buffers(2147352580, 536903681, true, true, true))
    EXPECT_GE(p.bytes, std::uint64_t(1) << 60) << p.what;
  EXPECT_GE(lucent::part_write_bytes(2147352580, 536903681, lucent::PartCompression::piz),
            std::uint64_t(1) << 60);
  // a reservation near 2^64 with a small film
  for (const std::uint64_t reserved :
       {std::uint64_t(1) << 63, ~std::uint64_t(0) - 99, ~std::uint64_t(0)})
    EXPECT_NE(refused(16, 16, lucent::render_detail::reserved_part(reserved)), "") << reserved;
  EXPECT_EQ(lucent::sys::host_block_bytes(~std::uint64_t(0) - 5), ~std::uint64_t(0));
}

// LUCENT_HUGE_PAGES is 0 or 1: another value ("off", "false") turned the advice on without a
// word; it is taken as 1 with a warning, once.
TEST(Resources, HugePagesVariableIsZeroOrOne) {
  lucent::test::ScopedEnv env("LUCENT_HUGE_PAGES", "off");
  lucent::test::CaptureWarnings w;  // (through the warning sink, as the other variables')
  for (int k = 0; k < 2; ++k)
    lucent::sys::release_host_block(
        lucent::sys::allocate_host_block(lucent::sys::kHugePageMinBuffer));
  ASSERT_EQ(w.all().size(), 1u) << w.dump();
  EXPECT_EQ(w.all()[0],
            "LUCENT_HUGE_PAGES='off' is neither 0 (no huge-page advice) nor 1 (the default); "
            "taken as 1");
}

// Before upload, per device: each buffer against the largest allocation, by its registry
// description, and all of them against global memory.
TEST(Resources, DeviceLimitsNameTheBuffer) {
  Scene s = lucent::test::scene_from(grid_scene(10, 16));
  s.path = "s.json";
  auto packed = lucent::render_detail::pack_scene(s);
  DeviceLimits d;
  d.device = "Tiny GPU";
  d.max_alloc = 4096;
  // 200 triangles: the largest buffer, named by its registry description, is refused
  std::string largest;
  std::size_t largest_bytes = 0;
#define LUCENT_LARGEST(name, type, what)                 \
  if (packed.name.size() * sizeof(type) > largest_bytes) \
    largest_bytes = packed.name.size() * sizeof(type), largest = what;
  LC_SCENE_BUFFERS(LUCENT_LARGEST)
#undef LUCENT_LARGEST
  ASSERT_GT(largest_bytes, 8192u);
  std::string msg = error_of([&] { lucent::render_detail::check_device_memory(s, packed, d); });
  EXPECT_EQ(msg.rfind("s.json: the " + largest + " need a buffer of ", 0), 0u) << msg;
  EXPECT_NE(msg.find(", more than the 4.0 KiB device 'Tiny GPU' allows per buffer "
                     "(CL_DEVICE_MAX_MEM_ALLOC_SIZE): reduce the number of triangles"),
            std::string::npos)
      << msg;
  // the film's buffers are checked too: 16 bytes per pixel
  d.max_alloc = 1 << 20;
  s.film.width = s.film.height = 512;
  EXPECT_EQ(error_of([&] { lucent::render_detail::check_device_memory(s, packed, d); }),
            "s.json: the film sample sums (512x512) need a buffer of 4.0 MiB, more than the 1.0 "
            "MiB device 'Tiny GPU' allows per buffer (CL_DEVICE_MAX_MEM_ALLOC_SIZE): reduce the "
            "film size");
  // every buffer fits, not all of them
  d.max_alloc = 0;
  d.global_mem = 6 << 20;
  msg = error_of([&] { lucent::render_detail::check_device_memory(s, packed, d); });
  // sums, sums of squares and the work list: 3 x 4 MiB
  EXPECT_EQ(msg.rfind("s.json: the scene and film buffers need 12.0 MiB on device 'Tiny GPU', "
                      "more than its 6.0 MiB of global memory (CL_DEVICE_GLOBAL_MEM_SIZE); the "
                      "largest is the film sample sums (512x512) (4.0 MiB): reduce the film size",
                      0),
            0u)
      << msg;
  d.global_mem = 13 << 20;
  EXPECT_EQ(error_of([&] { lucent::render_detail::check_device_memory(s, packed, d); }), "");
  // with caustics the light paths' sums and sums of squares take two more buffers of two films
  // each (an adaptive work list's halves A and B), and the sums and sums of squares are twice as
  // long (the light paths' totals after them): 4 x 8 + 4 MiB
  packed.params.flags |= LC_FLAG_CAUSTICS;
  msg = error_of([&] { lucent::render_detail::check_device_memory(s, packed, d); });
  EXPECT_EQ(msg.rfind("s.json: the scene and film buffers need 36.0 MiB on device 'Tiny GPU'", 0),
            0u)
      << msg;
}

// A session applies both checks before it allocates, and stays usable after a refusal.
TEST(Resources, SessionRefusesBeforeAllocatingAndRecovers) {
  Scene s = lucent::load_scene(textured_scene_file(64, 64, 32));  // 64 KiB of texels
  s.path = "t.json";
  lucent::Renderer r(lucent::test::session_options());
  {
    DeviceLimits lim;
    lim.host_mem = 64 << 10;
    ScopedLimitOverride o(lim);
    std::string msg = error_of([&] { r.set_scene(s); });
    EXPECT_NE(msg.find("t.json: rendering needs about "), std::string::npos) << msg;
    EXPECT_NE(msg.find("more than the limit of 64.0 KiB"), std::string::npos) << msg;
  }
  {
    DeviceLimits lim;
    lim.max_alloc = 32 << 10;
    ScopedLimitOverride o(lim);
    std::string msg = error_of([&] { r.set_scene(s); });
    EXPECT_NE(msg.find("t.json: the texture texels need a buffer of 64.0 KiB, more than the 32.0 "
                       "KiB device '"),
              std::string::npos)
        << msg;
    EXPECT_NE(msg.find("reduce the textures' resolution"), std::string::npos) << msg;
  }
  {
    DeviceLimits lim;
    lim.global_mem = 64 << 10;
    ScopedLimitOverride o(lim);
    std::string msg = error_of([&] { r.set_scene(s); });
    EXPECT_NE(msg.find("more than its 64.0 KiB of global memory (CL_DEVICE_GLOBAL_MEM_SIZE); "
                       "the largest is the texture texels (64.0 KiB)"),
              std::string::npos)
        << msg;
  }
  // a 100000 x 100000 film given through the library (the JSON loader's range check is not on
  // this path): refused by the host estimate, at once
  Scene huge = s;
  huge.film.width = huge.film.height = 100000;
  std::string msg = error_of([&] { r.set_scene(huge); });
  EXPECT_EQ(msg.rfind("t.json: rendering needs about ", 0), 0u) << msg;
  EXPECT_NE(msg.find(film_culprit("100000x100000", "745.1 GiB")), std::string::npos) << msg;
  // the limits back to the device's: the same session renders the scene
  r.set_scene(s);
  r.render(1);
  auto res = r.result();
  EXPECT_EQ(res.spp, 1u);
  EXPECT_NEAR(res.mean.rgb[(16 * 32 + 16) * 3], 0.5, 1e-3);  // albedo of the texture
}

// OpenCL's resource errors say what ran out, where and what to reduce; others are unchanged.
TEST(Resources, OutOfResourcesSaysWhatToReduce) {
  using lucent::render_detail::resource_error;
  EXPECT_EQ(resource_error(cl::Error(CL_MEM_OBJECT_ALLOCATION_FAILURE, "clCreateBuffer"),
                           ClStage::Upload, "s.json", "GPU"),
            "s.json: device 'GPU' ran out of memory or resources creating the scene and film "
            "buffers (clCreateBuffer: CL_MEM_OBJECT_ALLOCATION_FAILURE): reduce the film size, "
            "the textures' resolution or the number of triangles");
  EXPECT_EQ(resource_error(cl::Error(CL_OUT_OF_RESOURCES, "clEnqueueNDRangeKernel"), ClStage::Pass,
                           "s.json", "GPU"),
            "s.json: device 'GPU' ran out of memory or resources running a pass "
            "(clEnqueueNDRangeKernel: CL_OUT_OF_RESOURCES): reduce the film size, max_depth or "
            "the samples per pass (a shorter pass time)");
  EXPECT_EQ(resource_error(cl::Error(CL_OUT_OF_HOST_MEMORY, "clEnqueueReadBuffer"), ClStage::Pass,
                           "", "CPU"),
            "scene: device 'CPU' ran out of host memory reading a pass back "
            "(clEnqueueReadBuffer: CL_OUT_OF_HOST_MEMORY): reduce the film size");
  EXPECT_EQ(
      resource_error(cl::Error(CL_INVALID_VALUE, "clSetKernelArg"), ClStage::Pass, "s.json", "GPU"),
      "clSetKernelArg: CL_INVALID_VALUE");
}

/// Runs the CLI with at most 4 GiB of address space (but under AddressSanitizer); the time it
/// took.
lucent::test::CommandResult bounded_cli(const std::string& args, double* seconds) {
  auto t0 = std::chrono::steady_clock::now();
  auto r = lucent::test::run_cli(args, ulimit_v("4194304"));
  *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

void expect_one_line_refusal(const std::string& args, const std::string& expected) {
  double seconds = 0;
  auto r = bounded_cli(args, &seconds);
  EXPECT_NE(r.status, 0) << args;
  EXPECT_LT(seconds, 10) << args;
  EXPECT_EQ(lucent::test::count_lines(r.err), 1) << args << "\n" << r.err;
  EXPECT_NE(r.err.find(expected), std::string::npos) << args << "\n" << r.err;
}

// The host limit is 80% of the smallest of physical memory, the address-space limit and the
// cgroup's: under `ulimit -v` 2 GiB an 8192x8192 film is refused by the estimate (it made PoCL
// abort on an assertion when its buffer allocation failed, or ended in a bare 'out of memory').
TEST(Resources, AddressSpaceLimitBoundsTheHost) {
  if (kAddressSanitizer) GTEST_SKIP() << "AddressSanitizer cannot run under ulimit -v";
  std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/s.json", grid_scene(2, 4));
  auto t0 = std::chrono::steady_clock::now();
  auto r = lucent::test::run_cli("render " + q(dir + "/s.json") + " -o " + q(dir + "/o.png") +
                                     " --width 8192 --height 8192 --integrator albedo",
                                 ulimit_v("2097152"));
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_LT(seconds, 10);
  EXPECT_EQ(lucent::test::count_lines(r.err), 1) << r.err;
  // before any device is chosen: its buffers (host memory on a CPU device) come on top, so the
  // need is a lower bound (it said "about" the film's share, half of what lucent info counts)
  EXPECT_NE(r.err.find("rendering needs at least about 5.0 GiB of host memory before its devices' "
                       "buffers, more than the limit of 1.6 GiB (80% of the address-space "
                       "limit (ulimit -v)); " +
                       film_culprit("8192x8192", "5.0 GiB")),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(lucent::test::read_file(dir + "/o.png").size() > 0);
}

/// In a death test's child: write_render_exr of a 2048x2048 render with the address space
/// capped; exits 3 after printing its lucent::Error, 0 when the write succeeded.
[[noreturn]] void write_exr_under_cap(const std::string& path) {
  const int w = 2048, h = 2048;
  const size_t n = size_t(w) * h;
  lucent::RenderResult r;
  r.mean = lucent::Image{w, h, std::vector<float>(n * 3, 0.5f)};
  r.variance = lucent::Image{w, h, std::vector<float>(n * 3, 0.25f)};
  r.samples.assign(n, 4);
  // what the process maps now, plus the planes write_render_exr makes (24 bytes a pixel)
  // and 32 MiB: the encoder's twice 28 bytes a pixel cannot be had
  std::uint64_t vm_kib = 0;
  std::FILE* f = std::fopen("/proc/self/status", "r");
  char line[256];
  while (f && std::fgets(line, sizeof line, f))
    if (std::sscanf(line, "VmSize: %lu", &vm_kib) == 1) break;
  if (f) std::fclose(f);
  rlimit cap{};
  cap.rlim_cur = cap.rlim_max = vm_kib * 1024 + n * 24 + (32u << 20);
  if (vm_kib == 0 || setrlimit(RLIMIT_AS, &cap) != 0) std::exit(2);
  try {
    lucent::write_render_exr(path, r);
  } catch (const lucent::Error& e) {
    std::fprintf(stderr, "%s\n", e.what());
    std::exit(3);
  }
  std::exit(0);
}

// Short of memory at the end of a render, the EXR encoder (tinyexr, which does not check its
// allocations) wrote through a null pointer: a part file's render (--samples) under an
// address-space limit that its render fits ended in SIGSEGV without a word (the resources
// review). The memory the encoder needs is now asked for first: an error, no file. (Run in a
// child whose address space is capped just above what it holds with the image's planes.)
TEST(Resources, ExrEncoderShortOfMemoryIsAnErrorNotACrash) {
  if (kAddressSanitizer) GTEST_SKIP() << "AddressSanitizer cannot run under an address-space cap";
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const std::string path = lucent::test::temp_dir() + "/p.exr";
  EXPECT_EXIT(write_exr_under_cap(path), testing::ExitedWithCode(3),
              "p.exr: cannot encode EXR: not enough memory for its encoder");
  EXPECT_FALSE(std::filesystem::exists(path));
}

// Writing an output takes memory of its own after the render: a part file about 278 bytes a
// pixel at most (its sums, their 32-bit words, planes and the EXR encoder), against the
// session's 160. Under an address-space limit that the session's estimate fit, the render
// ran and its write then failed (the render lost) or crashed. It is now refused before
// rendering, naming the write.
TEST(Resources, OutputTooLargeToWriteIsRefusedBeforeRendering) {
  if (kAddressSanitizer) GTEST_SKIP() << "AddressSanitizer cannot run under ulimit -v";
  std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/s.json", grid_scene(2, 4));
  auto t0 = std::chrono::steady_clock::now();
  auto r = lucent::test::run_cli("render " + q(dir + "/s.json") + " -o " + q(dir + "/p.exr") +
                                     " --width 2048 --height 2048 --samples 0:1 -q",
                                 ulimit_v("1000000"));
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_LT(seconds, 10);
  EXPECT_EQ(lucent::test::count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("s.json: rendering needs about 1.1 GiB of host memory, more than the limit "
                       "of 781.2 MiB (80% of the address-space limit (ulimit -v)); the largest "
                       "part is writing "),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("p.exr (2048x2048) (906.5 MiB): reduce the film size"), std::string::npos)
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/p.exr"));
}

// The outputs that `lucent render --aov` or `--checkpoint` keeps beside the session are named as
// the command line gives them: the error said "what the application keeps beside the session (its
// outputs, as it declared them)", the library's wording, and named no --aov or checkpoint.
TEST(Resources, OutputsBesideTheSessionAreNamedByTheirOptions) {
  if (kAddressSanitizer) GTEST_SKIP() << "AddressSanitizer cannot run under ulimit -v";
  std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/s.json", grid_scene(2, 4));
  const std::string render = "render " + q(dir + "/s.json") + " -o " + q(dir + "/o.exr") +
                             " --width 4096 --height 4096 --spp 1 -q ";
  const std::pair<std::string, std::string> cases[] = {
      {"--aov albedo,depth",
       "the largest part is writing " + dir + "/o.exr and then each --aov image (4096x4096)"},
      {"--checkpoint " + q(dir + "/ck.exr"),
       "the largest part is the checkpoint's sums and the write of its file (4096x4096)"}};
  for (const auto& [options, named] : cases) {
    auto r = lucent::test::run_cli(render + options, ulimit_v("1500000"));
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_EQ(lucent::test::count_lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(named), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("): reduce the film size"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(std::filesystem::exists(dir + "/o.exr"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/ck.exr"));
}

// What an application keeps beside a session (SessionOptions::reserved_host_bytes: `lucent
// render` declares its outputs there) counts in the session's estimate.
TEST(Resources, SessionCountsWhatTheApplicationReserves) {
  Scene s = lucent::load_scene(textured_scene_file(64, 64, 32));
  s.path = "t.json";
  DeviceLimits lim;
  lim.host_mem = 8 << 20;
  ScopedLimitOverride o(lim);
  lucent::SessionOptions so = lucent::test::session_options();
  so.reserved_host_bytes = 10 << 20;
  {
    lucent::Renderer r(so);
    const std::string msg = error_of([&] { r.set_scene(s); });
    EXPECT_EQ(msg.rfind("t.json: rendering needs about ", 0), 0u) << msg;
    EXPECT_NE(msg.find("the largest part is what the application keeps beside the session (its "
                       "outputs, as it declared them) (10.0 MiB): reduce the film size, or what "
                       "the application declares it keeps"),
              std::string::npos)
        << msg;
  }
  {  // named as the application says (lucent render names its outputs by their options)
    so.reserved_host_what = "writing o.exr and then each --aov image (64x64)";
    lucent::Renderer r(so);
    const std::string msg = error_of([&] { r.set_scene(s); });
    EXPECT_NE(msg.find("the largest part is writing o.exr and then each --aov image (64x64) (10.0 "
                       "MiB): reduce the film size"),
              std::string::npos)
        << msg;
  }
  so.reserved_host_bytes = 1 << 20;
  lucent::Renderer r(so);
  EXPECT_EQ(error_of([&] { r.set_scene(s); }), "");
}

// The work-group size is 64 where the device and the kernel allow it, else the largest power of
// two they allow.
TEST(Resources, WorkGroupSizeFitsTheDeviceAndTheKernel) {
  using lucent::render_detail::work_group_size;
  EXPECT_EQ(work_group_size(64, 4096, 4096, 4096), 64u);
  EXPECT_EQ(work_group_size(64, 0, 0, 0), 64u) << "0: no limit known";
  EXPECT_EQ(work_group_size(64, 32, 4096, 4096), 32u);
  EXPECT_EQ(work_group_size(64, 1024, 48, 1024), 32u);
  EXPECT_EQ(work_group_size(64, 1024, 1024, 40), 32u);
  EXPECT_EQ(work_group_size(64, 1, 1, 1), 1u);
}

// A device whose work-groups are smaller than lucent's 64 (PoCL capped by
// POCL_MAX_WORK_GROUP_SIZE) renders, with the same image bit for bit: a sample's numbers do not
// depend on the work-group size. It failed with "clEnqueueNDRangeKernel:
// CL_INVALID_WORK_GROUP_SIZE" before.
TEST(Resources, SmallWorkGroupDeviceRendersTheSameImage) {
  std::string dir = lucent::test::temp_dir();
  lucent::test::write_file(dir + "/s.json", grid_scene(2, 4));
  const std::string args = "render " + q(dir + "/s.json") + " --width 24 --height 20 --spp 2 -o ";
  auto a = lucent::test::run_cli(args + q(dir + "/a.pfm") + " --quiet");
  auto b =
      lucent::test::run_cli(args + q(dir + "/b.pfm") + " --quiet", "POCL_MAX_WORK_GROUP_SIZE=8");
  ASSERT_EQ(a.status, 0) << a.err;
  ASSERT_EQ(b.status, 0) << b.err;
  EXPECT_EQ(b.err, "");
  const std::string pa = lucent::test::read_file(dir + "/a.pfm");
  EXPECT_GT(pa.size(), 24u * 20u * 12u);
  EXPECT_TRUE(pa == lucent::test::read_file(dir + "/b.pfm"));
}

// Each texture is bounded (8192 x 8192), and so are all of them together: as they load, the
// scene's textures as linear RGBA float, and the one being decoded with its decoder's buffers,
// must stay within the host limit. 40 names of one 1024 x 1024 run-length TGA (128 KiB, 16 MiB
// decoded) under `ulimit -v` 256 MiB: the 12th is refused.
TEST(Resources, TexturesTogetherAreBounded) {
  if (kAddressSanitizer) GTEST_SKIP() << "AddressSanitizer cannot run under ulimit -v";
  std::string dir = lucent::test::temp_dir();
  const int w = 1024, h = 1024;
  std::string tga = {0,
                     0,
                     10,
                     0,
                     0,
                     0,
                     0,
                     0,
                     0,
                     0,
                     0,
                     0,
                     char(w & 255),
                     char(w >> 8),
                     char(h & 255),
                     char(h >> 8),
                     24,
                     0x20};
  for (int i = 0; i < w * h / 128; ++i) tga += std::string("\xff\x28\x50\x78", 4);
  std::string materials;
  for (int i = 0; i < 40; ++i) {
    std::string name = "t" + std::to_string(i) + ".tga";
    lucent::test::write_file(dir + "/" + name, tga);
    char key[8];
    std::snprintf(key, sizeof key, "m%02d", i);
    materials += std::string(i ? "," : "") + "\"" + key +
                 "\": {\"type\": \"diffuse\", \"albedo\": {\"texture\": \"" + name + "\"}}";
  }
  lucent::test::write_file(dir + "/s.json", R"({"film": {"width": 4, "height": 4},
    "materials": {)" + materials + R"(},
    "shapes": [{"type": "sphere", "center": [0, 0, -3], "radius": 1, "material": "m00"}]})");
  auto r = lucent::test::run_cli("render " + q(dir + "/s.json") + " -o " + q(dir + "/o.png"),
                                 ulimit_v("262144"));
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(lucent::test::count_lines(r.err), 1) << r.err;
  // decoding a texture takes 32 bytes a pixel (its floats, stb_image's image and buffers): the
  // twelfth's 32 MiB beside the eleven's 176 (the thirteenth's 16 MiB was the first counted past
  // the limit, when only the textures' floats were)
  EXPECT_NE(r.err.find("/materials/m11/albedo/texture: " + dir +
                       "/t11.tga: decoding this 1024x1024 texture needs about 32.0 MiB beside "
                       "the scene's 11 texture(s) (176.0 MiB), more than the limit of 204.8 MiB "
                       "(80% of the address-space limit (ulimit -v)): reduce the textures' "
                       "resolution or number"),
            std::string::npos)
      << r.err;
}

// The issue's list: each ends in one line and a non-zero exit, within seconds and 4 GiB.
TEST(Resources, IssueCasesEndInOneLine) {
  std::string dir = lucent::test::temp_dir();
  std::string out = q(dir + "/o.png");
  auto scene = [&](const std::string& name, const std::string& json) {
    lucent::test::write_file(dir + "/" + name, json);
    return q(dir + "/" + name);
  };
  std::string small = scene("small.json", grid_scene(2, 4));

  // a 100000 x 100000 film, on the command line and in the scene
  expect_one_line_refusal("render " + small + " -o " + out + " --width 100000 --height 100000",
                          "--width: Value 100000 not in range 1 to 16384");
  expect_one_line_refusal(
      "render " + scene("film.json", R"({"film": {"width": 100000, "height": 100000}})") + " -o " +
          out,
      "/film/width: must be in [1, 16384], got 100000");
  // the largest film allowed needs 28 GiB of host memory (40 GiB on a CPU device with fp64):
  // refused here by the estimate before anything is allocated (on a machine with 35 GiB or more
  // it would be rendered)
  if (lucent::render_detail::host_memory_limit() < (std::uint64_t(28) << 30))
    expect_one_line_refusal(
        "render " + small + " -o " + out + " --width 16384 --height 16384 --integrator albedo",
        film_culprit("16384x16384", "20.0 GiB"));

  // a texture whose header claims 65535 x 65535, as a material's texture and an environment map
  std::string png = std::string("\x89PNG\r\n\x1a\n", 8);
  auto be32 = [](std::uint32_t v) {
    return std::string{char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
  };
  png += be32(13) + "IHDR" + be32(65535) + be32(65535) + std::string("\x08\x02\x00\x00\x00", 5) +
         be32(0);
  lucent::test::write_file(dir + "/huge.png", png);
  expect_one_line_refusal(
      "render " +
          scene("tex.json",
                R"({"materials": {"m": {"type": "diffuse", "albedo": {"texture": "huge.png"}}},
                    "shapes": [{"type": "sphere", "center": [0, 0, -3], "radius": 1,
                                "material": "m"}]})") +
          " -o " + out,
      "PNG header claims 65535x65535 pixels, more than the limit of 67108864 pixels");
  expect_one_line_refusal(
      "render " +
          scene("env.json", R"({"lights": [{"type": "environment_map", "file": "huge.png"}]})") +
          " -o " + out,
      "PNG header claims 65535x65535 pixels");

  // JSON nested 10^5 deep
  std::string deep = "{\"camera\": ";
  for (int i = 0; i < 100000; ++i) deep += "[";
  expect_one_line_refusal("render " + scene("deep.json", deep) + " -o " + out,
                          "nested deeper than 64 levels");

  // 10^9 spp: option, scene integer, scene number
  expect_one_line_refusal("render " + small + " -o " + out + " --spp 1000000000",
                          "--spp: Value 1000000000 not in range 1 to 16777216");
  expect_one_line_refusal(
      "render " + scene("spp.json", R"({"integrator": {"spp": 1000000000}})") + " -o " + out,
      "/integrator/spp: must be in [1, 16777216], got 1000000000");
  expect_one_line_refusal(
      "render " + scene("spp2.json", R"({"integrator": {"spp": 1e9}})") + " -o " + out,
      "/integrator/spp: must be an integer");

  // max_depth 10^9
  expect_one_line_refusal("render " +
                              scene("depth.json", R"({"integrator": {"max_depth": 1000000000}})") +
                              " -o " + out,
                          "/integrator/max_depth: must be in [1, 100000], got 1000000000");
}

}  // namespace

// An adaptive render keeps three halves, two pilots and the plans on the host, about four times a
// uniform render's accumulation: a host limit that a uniform render fits under refuses the
// adaptive one in one line naming that part, before it allocates, and the session still renders
// uniformly afterwards.
TEST(Resources, AdaptiveRenderChecksItsHostMemory) {
  Scene s = lucent::test::scene_from(grid_scene(4, 4));
  s.path = "a.json";
  s.film.width = s.film.height = 256;
  lucent::Renderer r(lucent::test::session_options());
  DeviceLimits cpu;  // PoCL's CPU device: its buffers are host memory
  cpu.device = r.device().name;
  cpu.host_unified = true;
  std::vector<DeviceLimits> devices = {cpu};
  std::uint64_t uniform = 0;
  for (const auto& p : lucent::render_detail::estimate_host_memory(s, devices)) uniform += p.bytes;
  const std::uint64_t extra = lucent::render_detail::adaptive_host_bytes(256u * 256, false);
  ASSERT_GT(extra, uniform / 2);
  DeviceLimits lim;
  lim.host_mem = uniform + extra / 2;
  ScopedLimitOverride o(lim);
  r.set_scene(s);
  lucent::AdaptiveOptions ao;
  ao.target_error = 1e-2;
  std::string msg = error_of([&] { r.render_adaptive(ao); });
  EXPECT_EQ(msg.rfind("a.json: rendering needs about ", 0), 0u) << msg;
  EXPECT_NE(msg.find("the largest part is the halves, pilots and plans of adaptive sampling for "
                     "the 256x256 film"),
            std::string::npos)
      << msg;
  EXPECT_NE(msg.find("reduce the film size, or render a fixed number of samples"),
            std::string::npos)
      << msg;
  r.render(1);  // the uniform render was never refused
  EXPECT_EQ(r.result().spp, 1u);
}

// The CPU reference checks its host memory before it allocates, as the kernel's renders do: its
// accumulation, and with caustics one set of light sums per thread (64 threads of 48 bytes per
// pixel for a 4096x4096 film were 51 GiB, allocated unchecked and zero-filled).
TEST(Resources, ReferenceChecksItsHostMemory) {
  Scene s = lucent::test::scene_from(grid_scene(4, 4));
  s.path = "r.json";
  s.film.width = s.film.height = 256;
  lucent::ReferenceOptions ro;
  ro.spp = 1;
  ro.threads = 1;
  std::uint64_t need = 0;
  for (const auto& p : lucent::render_detail::estimate_host_memory(s, {})) need += p.bytes;
  DeviceLimits lim;
  lim.host_mem = need - 1;
  {
    ScopedLimitOverride o(lim);
    std::string msg = error_of([&] { lucent::render_reference(s, ro); });
    EXPECT_EQ(msg.rfind("r.json: rendering needs about ", 0), 0u) << msg;
    EXPECT_NE(msg.find("the largest part is the accumulation and result images of the 256x256 "
                       "film"),
              std::string::npos)
        << msg;
  }
  // with caustics (a path tracer's option), the light sums of every thread (a mirror or not:
  // the reference traces light paths whenever caustics are asked for)
  s.integrator.type = lucent::IntegratorType::Path;
  s.integrator.caustics = true;
  s.film.width = s.film.height = 64;
  ro.threads = 16;
  need = 0;
  for (const auto& p : lucent::render_detail::estimate_host_memory(s, {})) need += p.bytes;
  // room for the light sums of 9 threads, not 16 (the kernel's estimate has none: no mirror)
  lim.host_mem = need + 64u * 64 * 48 * 9;
  {
    ScopedLimitOverride o(lim);
    std::string msg = error_of([&] { lucent::render_reference(s, ro); });
    EXPECT_NE(msg.find("the largest part is the caustics light sums of the 64x64 film, one per "
                       "thread (16)"),
              std::string::npos)
        << msg;
    EXPECT_NE(msg.find("reduce the film size or the reference's threads"), std::string::npos)
        << msg;
    ro.threads = 8;
    EXPECT_EQ(error_of([&] { lucent::render_reference(s, ro); }), "");
  }
}

// The kernel reaches texels through 32-bit offsets: textures holding more are refused when the
// scene is packed (the memory checks refuse them on most devices, not on a large host's PoCL,
// where the offsets wrapped). The texture here only claims its size: the check reads no texel.
TEST(Resources, TexelsBeyondTheKernelsOffsetsAreRefused) {
  Scene s = lucent::test::scene_from(grid_scene(1, 4));
  s.path = "t.json";
  lucent::Texture t;
  t.width = t.height = 70000;
  s.textures.push_back(t);
  EXPECT_EQ(error_of([&] { lucent::render_detail::pack_scene(s); }),
            "t.json: the textures hold 4900000000 texels, more than the kernel's 32-bit texel "
            "offsets reach (4294967295): reduce the textures' resolution");
}

}  // namespace test_resources
