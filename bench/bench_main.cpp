// lucent_bench: BVH build speed and quality, and kernel traversal speed, on the Stanford bunny,
// the dragon (../shared/assets/meshes, skipped when absent) and a generated 1M-triangle mesh.
// When built with Embree 3 the same rays are traced through Embree (rtcIntersect1, 2 threads),
// alternating with lucent's kernel round by round (best of --reps rounds each), and lucent's speed
// is reported as a fraction of Embree's. Figures: BENCHMARKS.md.
//
// usage: lucent_bench [--runs N] [--reps N] [--width W] [--height H] [--device SELECTOR]
//                     [--threads N] [--build-only] [--only NAME] [--no-embree]
//                     [--traversal-cost C] [--max-leaf N] [--leaf-block N] [--reorder]
//                     [--embree-quality low|medium|high] [--embree-robust]
// --embree-quality: Embree's build quality (default medium, Embree's own default; Mitsuba 3 builds
// with high, which adds spatial splits). --embree-robust: RTC_SCENE_FLAG_ROBUST, Embree's
// watertight mode (lucent's triangle test is watertight; Mitsuba 3 leaves the flag off).
#include <tiny_obj_loader.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "bvh/bvh.hpp"
#include "cl/context.hpp"
#include "lucent/error.hpp"
#include "support/device_tracer.hpp"
#include "support/reorder.hpp"
#include "support/test_meshes.hpp"

#ifdef LUCENT_BENCH_EMBREE
#include <embree3/rtcore.h>
#endif

namespace {

using lucent::bvh::TraceHit;
using lucent::bvh::TraceRay;

struct Options {
  int runs = 5;
  int reps = 5;  // traversal timing rounds (lucent and Embree alternating), best of each
  int width = 640, height = 480;
  int threads = 0;          // BVH build threads, 0: all cores
  bool build_only = false;  // skip the traversal figures
  std::string only;         // run only the meshes whose name contains this
  bool embree = true;       // compare with Embree when built with it
  float traversal_cost = lucent::bvh::BuildOptions().traversal_cost;
  int leaf_block = lucent::bvh::BuildOptions().leaf_block;
  int max_leaf = lucent::bvh::BuildOptions().max_leaf_size;
  bool reorder = false;  // trace triangles stored in leaf order (bvh::reorder_triangles)
  std::string device;
#ifdef LUCENT_BENCH_EMBREE
  RTCBuildQuality embree_quality = RTC_BUILD_QUALITY_MEDIUM;
  bool embree_robust = false;
#endif
};

bool load_obj(const std::string& path, std::vector<lc_triangle>& out) {
  std::ifstream probe(path);
  if (!probe) return false;
  tinyobj::ObjReaderConfig cfg;
  cfg.triangulate = true;
  cfg.vertex_color = false;
  tinyobj::ObjReader reader;
  if (!reader.ParseFromFile(path, cfg)) {
    std::fprintf(stderr, "%s: %s\n", path.c_str(), reader.Error().c_str());
    return false;
  }
  const auto& v = reader.GetAttrib().vertices;
  for (const auto& shape : reader.GetShapes()) {
    const auto& idx = shape.mesh.indices;
    for (std::size_t i = 0; i + 2 < idx.size(); i += 3) {
      lc_triangle t{};
      float* dst[3] = {t.v0, t.v1, t.v2};
      for (int k = 0; k < 3; ++k)
        for (int a = 0; a < 3; ++a) dst[k][a] = v[3 * idx[i + k].vertex_index + a];
      t.light = LC_INVALID;
      // leave out zero-area triangles, as src/render/pack.cpp does
      double e1[3], e2[3];
      for (int a = 0; a < 3; ++a) {
        e1[a] = double(t.v1[a]) - t.v0[a];
        e2[a] = double(t.v2[a]) - t.v0[a];
      }
      double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2],
             cz = e1[0] * e2[1] - e1[1] * e2[0];
      if (cx * cx + cy * cy + cz * cz > 0) out.push_back(t);
    }
  }
  return true;
}

struct V3 {
  double x, y, z;
};
V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V3 operator*(double s, V3 a) { return {s * a.x, s * a.y, s * a.z}; }
double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V3 cross(V3 a, V3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
V3 normalize(V3 a) { return (1.0 / std::sqrt(dot(a, a))) * a; }
V3 load(const float* p) { return {p[0], p[1], p[2]}; }

TraceRay make_ray(V3 o, V3 d) {
  TraceRay r{};
  r.o[0] = float(o.x), r.o[1] = float(o.y), r.o[2] = float(o.z);
  r.d[0] = float(d.x), r.d[1] = float(d.y), r.d[2] = float(d.z);
  r.tmax = INFINITY;
  return r;
}

// A camera at 2.2 bounding radii looking at the centre of the mesh, 40 degrees vertical fov.
std::vector<TraceRay> primary_rays(const lucent::bvh::Bvh& bvh, int w, int h) {
  V3 lo = load(bvh.bmin), hi = load(bvh.bmax);
  V3 c = 0.5 * (lo + hi);
  double radius = 0.5 * std::sqrt(dot(hi - lo, hi - lo));
  V3 fwd = normalize(V3{-0.35, -0.3, -1});
  V3 pos = c - 2.2 * radius * fwd;
  V3 right = normalize(cross(fwd, V3{0, 1, 0}));
  V3 up = cross(right, fwd);
  double th = std::tan(20.0 * M_PI / 180.0), aspect = double(w) / h;
  std::vector<TraceRay> rays;
  rays.reserve(std::size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double sx = (2 * (x + 0.5) / w - 1) * th * aspect, sy = (1 - 2 * (y + 0.5) / h) * th;
      rays.push_back(make_ray(pos, normalize(fwd + sx * right + sy * up)));
    }
  return rays;
}

// Cosine-distributed rays leaving the primary hit points (geometric normal towards the camera).
std::vector<TraceRay> diffuse_rays(const std::vector<TraceRay>& primary,
                                   const std::vector<TraceHit>& hits,
                                   const std::vector<lc_triangle>& tris, double scale) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u01(0, 1);
  std::vector<TraceRay> out;
  for (std::size_t i = 0; i < hits.size(); ++i) {
    if (hits[i].prim == LC_INVALID) continue;
    const lc_triangle& t = tris[hits[i].prim];
    V3 d = load(primary[i].d);
    V3 p = load(primary[i].o) + double(hits[i].t) * d;
    V3 n = normalize(cross(load(t.v1) - load(t.v0), load(t.v2) - load(t.v0)));
    if (dot(n, d) > 0) n = -1.0 * n;
    V3 a = std::fabs(n.x) > 0.5 ? V3{0, 1, 0} : V3{1, 0, 0};
    V3 tu = normalize(cross(a, n)), tv = cross(n, tu);
    double r = std::sqrt(u01(rng)), phi = 2 * M_PI * u01(rng);
    V3 dir = normalize(r * std::cos(phi) * tu + r * std::sin(phi) * tv +
                       std::sqrt(std::max(0.0, 1 - r * r)) * n);
    out.push_back(make_ray(p + 1e-5 * scale * n, dir));
  }
  return out;
}

#ifdef LUCENT_BENCH_EMBREE
double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct Embree {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  double build_seconds = 0;
  Embree(const std::vector<lc_triangle>& tris, RTCBuildQuality quality, bool robust) {
    device = rtcNewDevice("threads=2");
    double t0 = now();
    scene = rtcNewScene(device);
    rtcSetSceneBuildQuality(scene, quality);
    rtcSetSceneFlags(scene, robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    float* v = static_cast<float*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * tris.size()));
    unsigned* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), tris.size()));
    for (std::size_t i = 0; i < tris.size(); ++i) {
      std::memcpy(v + 9 * i, tris[i].v0, 12);
      std::memcpy(v + 9 * i + 3, tris[i].v1, 12);
      std::memcpy(v + 9 * i + 6, tris[i].v2, 12);
      for (int k = 0; k < 3; ++k) idx[3 * i + k] = unsigned(3 * i + k);
    }
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(scene);
    build_seconds = now() - t0;
  }
  ~Embree() {
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
  }
  // seconds to trace all rays with rtcIntersect1 on 2 threads; fills hits
  double trace(const std::vector<TraceRay>& rays, std::vector<TraceHit>& hits) {
    hits.assign(rays.size(), TraceHit{});
    double t0 = now();
    auto work = [&](std::size_t b, std::size_t e) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      for (std::size_t i = b; i < e; ++i) {
        RTCRayHit rh{};
        const TraceRay& r = rays[i];
        rh.ray.org_x = r.o[0], rh.ray.org_y = r.o[1], rh.ray.org_z = r.o[2];
        rh.ray.dir_x = r.d[0], rh.ray.dir_y = r.d[1], rh.ray.dir_z = r.d[2];
        rh.ray.tnear = 0, rh.ray.tfar = r.tmax, rh.ray.mask = ~0u;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(scene, &ctx, &rh);
        hits[i].t = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? INFINITY : rh.ray.tfar;
        hits[i].prim = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? LC_INVALID : rh.hit.primID;
      }
    };
    std::size_t half = rays.size() / 2;
    std::thread other(work, half, rays.size());
    work(0, half);
    other.join();
    return now() - t0;
  }
};
#endif

void bench_mesh(const std::string& name, const std::vector<lc_triangle>& tris, const Options& opt,
                lucent::cl_util::Context& ctx) {
  std::printf("\n== %s: %zu triangles\n", name.c_str(), tris.size());
  std::vector<double> times;
  lucent::bvh::Bvh bvh;
  for (int r = 0; r < opt.runs; ++r) {
    lucent::bvh::BuildOptions bo;
    bo.threads = opt.threads;
    bo.traversal_cost = opt.traversal_cost;
    bo.leaf_block = opt.leaf_block;
    bo.max_leaf_size = opt.max_leaf;
    bvh = lucent::bvh::build(tris, {}, bo);
    times.push_back(bvh.stats.seconds);
  }
  std::sort(times.begin(), times.end());
  const auto& s = bvh.stats;
  double median = times[times.size() / 2];
  std::printf("build: median %.1f ms (best %.1f ms) over %d runs = %.2f Mtris/s\n", median * 1e3,
              times.front() * 1e3, opt.runs, tris.size() / median * 1e-6);
  std::printf(
      "tree:  binary %zu nodes, max depth %zu, SAH cost %.2f; %d-wide %zu nodes, max depth %zu; "
      "%zu leaves, mean leaf %.2f, max leaf %zu\n",
      s.binary_nodes, s.binary_max_depth, s.sah_cost, LC_BVH_WIDTH, s.nodes, s.max_depth, s.leaves,
      s.mean_leaf_size, s.max_leaf_size);
  if (opt.build_only) return;

  std::vector<lc_triangle> stored = tris;
  if (opt.reorder) lucent::bvh::reorder_triangles(bvh, stored);
  // LUCENT_KERNEL_DIR: the kernel sources from there, as the CLI reads them (kernel experiments)
  const char* kernel_dir = std::getenv("LUCENT_KERNEL_DIR");
  lucent::bvh::DeviceTracer tracer(ctx, stored, {}, bvh, "", "", kernel_dir ? kernel_dir : "");
  double scale = 0;
  for (int a = 0; a < 3; ++a) scale = std::max(scale, double(bvh.bmax[a] - bvh.bmin[a]));
  auto primary = primary_rays(bvh, opt.width, opt.height);
  tracer.trace(primary);  // warm-up: PoCL compiles the work-group function on first launch
  std::vector<TraceHit> phits = tracer.trace(primary), dhits;
  auto diffuse = diffuse_rays(primary, phits, stored, scale);
  dhits = tracer.trace(diffuse);
  std::size_t ph = 0, dh = 0;
  for (auto& h : phits) ph += h.prim != LC_INVALID;
  for (auto& h : dhits) dh += h.prim != LC_INVALID;
#ifdef LUCENT_BENCH_EMBREE
  std::unique_ptr<Embree> em;
  std::vector<TraceHit> eh;
  if (opt.embree) {
    em = std::make_unique<Embree>(tris, opt.embree_quality, opt.embree_robust);
    em->trace(primary, eh);  // warm-up
  }
#endif
  // lucent and Embree alternate, best time of each over opt.reps rounds: both see the same load
  double tp = INFINITY, td = INFINITY;
#ifdef LUCENT_BENCH_EMBREE
  double ep = INFINITY, ed = INFINITY;
#endif
  for (int r = 0; r < opt.reps; ++r) {
    tracer.trace(primary);
    tp = std::min(tp, tracer.last_kernel_seconds());
#ifdef LUCENT_BENCH_EMBREE
    if (em) ep = std::min(ep, em->trace(primary, eh));
#endif
    tracer.trace(diffuse);
    td = std::min(td, tracer.last_kernel_seconds());
#ifdef LUCENT_BENCH_EMBREE
    if (em) ed = std::min(ed, em->trace(diffuse, eh));
#endif
  }
  double mp = primary.size() / tp * 1e-6, md = diffuse.size() / td * 1e-6;
  std::printf(
      "lucent kernel: primary %zu rays (%.0f%% hit) %.2f Mrays/s; diffuse %zu rays "
      "(%.0f%% hit) %.2f Mrays/s\n",
      primary.size(), 100.0 * ph / primary.size(), mp, diffuse.size(),
      100.0 * dh / std::max<std::size_t>(1, diffuse.size()), md);
#ifdef LUCENT_BENCH_EMBREE
  if (!em) return;
  em->trace(primary, eh);
  std::size_t agree = 0, total = eh.size();
  for (std::size_t i = 0; i < eh.size(); ++i)
    agree += (eh[i].prim == LC_INVALID) == (phits[i].prim == LC_INVALID);
  double emp = primary.size() / ep * 1e-6, emd = diffuse.size() / ed * 1e-6;
  std::printf(
      "embree %d.%d.%d (rtcIntersect1, 2 threads, build %.1f ms): primary %.2f Mrays/s, "
      "diffuse %.2f Mrays/s; hit/miss agreement on primary rays %.4f%%\n",
      RTC_VERSION_MAJOR, RTC_VERSION_MINOR, RTC_VERSION_PATCH, em->build_seconds * 1e3, emp, emd,
      100.0 * agree / total);
  std::printf("lucent / embree: primary %.3f, diffuse %.3f\n", mp / emp, md / emd);
#endif
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "lucent_bench: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    // a whole number in [lo, hi], or exit 2 naming the option ("abc" was read as 0 and clamped
    // to 1, so --width abc measured 1-pixel frames without a word)
    auto integer = [&](long lo, long hi) -> int {
      const std::string v = next();
      char* end = nullptr;
      errno = 0;
      long n = std::strtol(v.c_str(), &end, 10);
      if (v.empty() || *end != '\0' || errno == ERANGE || n < lo || n > hi) {
        std::fprintf(stderr, "lucent_bench: %s: '%s' is not a whole number from %ld to %ld\n",
                     a.c_str(), v.c_str(), lo, hi);
        std::exit(2);
      }
      return int(n);
    };
    if (a == "--runs")
      opt.runs = integer(1, 100000);
    else if (a == "--reps")
      opt.reps = integer(1, 100000);
    else if (a == "--width")
      opt.width = integer(1, 16384);
    else if (a == "--height")
      opt.height = integer(1, 16384);
    else if (a == "--device")
      opt.device = next();
    else if (a == "--threads")
      opt.threads = integer(0, 4096);
    else if (a == "--build-only")
      opt.build_only = true;
    else if (a == "--only")
      opt.only = next();
    else if (a == "--no-embree")
      opt.embree = false;
    else if (a == "--reorder")
      opt.reorder = true;
    else if (a == "--leaf-block")
      opt.leaf_block = integer(1, 1 << 20);
    else if (a == "--max-leaf")
      opt.max_leaf = integer(1, 1 << 20);
    else if (a == "--traversal-cost") {
      const std::string v = next();
      char* end = nullptr;
      double c = std::strtod(v.c_str(), &end);
      if (v.empty() || *end != '\0' || !(c >= 0 && c < 1e6)) {
        std::fprintf(stderr, "lucent_bench: --traversal-cost: '%s' is not a number from 0\n",
                     v.c_str());
        return 2;
      }
      opt.traversal_cost = float(c);
    }
#ifdef LUCENT_BENCH_EMBREE
    else if (a == "--embree-quality") {
      std::string q = next();
      if (q == "low")
        opt.embree_quality = RTC_BUILD_QUALITY_LOW;
      else if (q == "medium")
        opt.embree_quality = RTC_BUILD_QUALITY_MEDIUM;
      else if (q == "high")
        opt.embree_quality = RTC_BUILD_QUALITY_HIGH;
      else {
        std::fprintf(stderr, "lucent_bench: --embree-quality: low, medium or high\n");
        return 2;
      }
    } else if (a == "--embree-robust")
      opt.embree_robust = true;
#else
    else if (a == "--embree-quality" || a == "--embree-robust") {
      std::fprintf(stderr,
                   "lucent_bench: %s: this lucent_bench was built without Embree 3 (install "
                   "libembree-dev, scripts/install-deps.sh --with-bench, and configure again)\n",
                   a.c_str());
      return 2;
    }
#endif
    else {
      std::fprintf(stderr,
                   "usage: lucent_bench [--runs N] [--reps N] [--width W] [--height H] "
                   "[--device S] [--threads N] [--build-only] [--only NAME] [--no-embree] "
                   "[--traversal-cost C] [--max-leaf N] [--leaf-block N] [--reorder] "
                   "[--embree-quality low|medium|high] [--embree-robust]\n");
      return 2;
    }
  }
  const char* const names[] = {"stanford-bunny.obj", "dragon.obj", "generated bumpy torus"};
  if (!opt.only.empty() && std::none_of(std::begin(names), std::end(names), [&](const char* n) {
        return std::string(n).find(opt.only) != std::string::npos;
      })) {
    std::fprintf(stderr,
                 "lucent_bench: --only %s matches none of stanford-bunny.obj, dragon.obj, "
                 "generated bumpy torus\n",
                 opt.only.c_str());
    return 2;
  }
  try {
    lucent::cl_util::Context ctx(opt.device);
    std::string load;
    std::ifstream("/proc/loadavg") >> load;  // other work on the machine skews every figure
    std::printf("device: %s (%s); host threads: %u; load average at start: %s\n",
                ctx.device.info.name.c_str(), ctx.device.info.platform.c_str(),
                std::thread::hardware_concurrency(), load.empty() ? "?" : load.c_str());
    const std::string dir = std::string(LUCENT_SHARED_DIR) + "/assets/meshes/";
    auto wanted = [&](const std::string& name) {
      return opt.only.empty() || name.find(opt.only) != std::string::npos;
    };
    for (const char* name : {names[0], names[1]}) {
      if (!wanted(name)) continue;
      std::vector<lc_triangle> tris;
      if (!load_obj(dir + name, tris)) {
        std::printf("\n== %s: not found in %s, skipped\n", name, dir.c_str());
        continue;
      }
      bench_mesh(name, tris, opt, ctx);
    }
    // 1000 x 500 x 2 = 1M triangles: a bumpy torus
    if (wanted(names[2])) {
      auto torus = lucent::bvh::meshes::torus(1000, 500, 1.0f, 0.35f, 0.15f).triangles();
      bench_mesh(names[2], torus, opt, ctx);
    }
  } catch (const lucent::Error& e) {
    std::fprintf(stderr, "lucent_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
