// The render session (lucent/session.hpp): one device, the kernel programs built for it (one per
// set of build options), one packed scene on the device and the accumulation of its samples in
// double on the host. lucent::render() (renderer.cpp) is a one-shot session.
#include "lucent/session.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <thread>

#include "cl/context.hpp"
#include "cl/kernel_source.hpp"
#include "cl/program_cache.hpp"
#include "core/host_memory.hpp"
#include "lucent/error.hpp"
#include "lucent/types.hpp"
#include "render/adaptive.hpp"
#include "render/cancel_scope.hpp"
#include "render/device_scene.hpp"
#include "render/features.hpp"
#include "render/pack.hpp"
#include "render/resources.hpp"
#include "render/sample_stats.hpp"
#include "scene/loaders.hpp"
#include "scene/validate.hpp"

namespace lucent {

namespace {

/// 64-bit FNV-1a.
std::uint64_t fnv1a(const void* data, std::size_t size) {
  const unsigned char* p = static_cast<const unsigned char*>(data);
  std::uint64_t h = 14695981039346656037ull;
  for (std::size_t i = 0; i < size; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

using clock_type = std::chrono::steady_clock;

// The work-group size: 64 wherever the device and the built kernel allow it (fixed: each new size
// costs PoCL a work-group compile); else the largest power of two they allow (devices whose
// CL_DEVICE_MAX_WORK_GROUP_SIZE, or a kernel whose CL_KERNEL_WORK_GROUP_SIZE, is below 64).
constexpr size_t kWorkGroupSize = 64;

double seconds_since(clock_type::time_point t) {
  return std::chrono::duration<double>(clock_type::now() - t).count();
}

std::string env_or_empty(const char* name) {
  const char* v = std::getenv(name);
  return v ? std::string(v) : std::string();
}

/// The cache directory a session uses: "" disabled.
std::string resolve_cache_dir(const std::string& dir) {
  if (dir == "off") return "";
  if (!dir.empty()) return dir;
  return cl_util::default_program_cache_dir();
}

/// The launch parameters and every buffer of two packings are the same: they render the same
/// image (with the same build options).
bool same_render_data(const render_detail::PackedScene& a, const render_detail::PackedScene& b) {
  if (std::memcmp(&a.params, &b.params, sizeof(lc_params)) != 0) return false;
  bool same = true;
#define LUCENT_SAME(name, type, ...)               \
  same = same && a.name.size() == b.name.size() && \
         (a.name.empty() ||                        \
          std::memcmp(a.name.data(), b.name.data(), a.name.size() * sizeof(type)) == 0);
  LC_SCENE_BUFFERS(LUCENT_SAME)
#undef LUCENT_SAME
  return same;
}

/// What one pass counted (its counters, kernels/shared/types.h).
struct PassCounts {
  std::uint64_t nonfinite = 0;  ///< samples whose radiance was not finite
  std::uint64_t rays = 0;
};

struct Program {
  cl::Program program;
  cl::Kernel kernel;
  size_t work_group = kWorkGroupSize;  ///< render_detail::work_group_size for this kernel
  bool cache_hit = false;
  double build_seconds = 0;
  /// FNV-1a of the kernel source it was built from (the embedded copy or kernel_dir's): part of
  /// image_hash, so that parts rendered by different kernels do not merge
  std::uint64_t source_hash = 0;
};

/// A pass output buffer's contents on the host, from `fetch` until the next `release`: on a
/// device whose buffers are host memory (a CPU device) the buffer itself, mapped for reading
/// (no copy: with fp64 sums 64 bytes per pixel less host memory), else a copy read into `copy`.
template <class T>
struct HostView {
  std::vector<T> copy;
  const T* data = nullptr;
  cl::Buffer mapped_buffer;  // set while mapped
  void* mapped = nullptr;

  /// Enqueues the read (or the map) of the first `n` elements of `b`; valid once the queue has
  /// finished it.
  void fetch(cl::CommandQueue& q, const cl::Buffer& b, size_t n, bool map) {
    release(q);
    if (map) {
      mapped = q.enqueueMapBuffer(b, CL_FALSE, CL_MAP_READ, 0, n * sizeof(T));
      mapped_buffer = b;
      data = static_cast<const T*>(mapped);
    } else {
      copy.resize(n);
      q.enqueueReadBuffer(b, CL_FALSE, 0, n * sizeof(T), copy.data());
      data = copy.data();
    }
  }
  /// Enqueues the unmap, before anything writes the buffer again or releases it.
  void release(cl::CommandQueue& q) {
    if (mapped) q.enqueueUnmapMemObject(mapped_buffer, mapped);
    mapped = nullptr;
    mapped_buffer = cl::Buffer();
    data = copy.empty() ? nullptr : copy.data();
  }
  /// Frees the copy (its buffer is gone).
  void drop(cl::CommandQueue& q) {
    release(q);
    std::vector<T>().swap(copy);
    data = nullptr;
  }
  const T& operator[](size_t k) const { return data[k]; }
};

/// One device of a session: its context, the programs built for it, the scene's buffers on it,
/// the pass output buffers, and its part of the work.
struct Worker {
  cl_util::Context ctx;
  std::map<std::string, Program> programs;  // by build options
  Program* program = nullptr;
  std::optional<render_detail::DeviceScene> dev;
  size_t npix = 0;
  cl::Buffer b_work, b_sum, b_sumsq, b_counters;  // work list: npix entries at most
  // caustics: the light paths' splats, one element without caustics; elements [0, npix) a uniform
  // pass's, [h npix, (h + 1) npix) a work list's half h's (megakernel.cl): npix elements until an
  // adaptive render needs 2 npix (ensure_light)
  cl::Buffer b_light, b_lightsq;
  bool light_buffers = false;
  size_t light_elems = 0;
  // a pass's sums as the kernel writes them: double4 where the device has fp64 (accum_double:
  // LC_ACCUM_DOUBLE, render_detail::device_defines; h_sum, h_sumsq), else float4 (h_sum_f,
  // h_sumsq_f); read through sum_at and sumsq_at. The light sums likewise: double4 where the
  // device has fp64 and 64-bit atomics (light_double: LC_LIGHT_DOUBLE; h_light, h_lightsq), else
  // float4 (h_light_f, h_lightsq_f); read through light_at and lightsq_at. Mapped, not copied,
  // where the device's buffers are host memory (map_results: a CPU device, as resources.cpp
  // counts it).
  bool accum_double = false;
  bool light_double = false;
  bool map_results = false;
  HostView<cl_double4> h_sum, h_sumsq, h_light, h_lightsq;
  HostView<cl_float4> h_sum_f, h_sumsq_f, h_light_f, h_lightsq_f;
  std::uint32_t pass_spp = 1;  // samples per pixel of its next pass (tuned to pass_seconds)
  DeviceShare share;           // of the accumulation
  DeviceShare call;            // of the render call in progress
  // an adaptive render's camera samples (all pixels) behind share and call: their per-pixel
  // counts are these divided by the film's pixels, not a sum of truncated per-job quotients
  std::uint64_t share_samples = 0, call_samples = 0;

  explicit Worker(const std::string& selector)
      : ctx(selector, "device"),
        accum_double(ctx.device.info.fp64),
        light_double(render_detail::light_sums_double(ctx.device.info)),
        map_results(render_detail::buffers_in_host_memory(ctx.device.device)) {
    share.device = call.device = ctx.device.info.name;
  }
  Worker(const Worker&) = delete;
  Worker& operator=(const Worker&) = delete;
  ~Worker() {
    if (!map_results) return;
    try {  // no mapping outlives its buffer
      release_results();
      ctx.queue.finish();
    } catch (...) {
    }
  }

  /// Unmaps the last pass's results: before a launch writes the buffers or they are replaced.
  void release_results() {
    for (HostView<cl_double4>* v : {&h_sum, &h_sumsq, &h_light, &h_lightsq}) v->release(ctx.queue);
    for (HostView<cl_float4>* v : {&h_sum_f, &h_sumsq_f, &h_light_f, &h_lightsq_f})
      v->release(ctx.queue);
  }

  /// A pass output buffer of `bytes`: on a CPU device host memory the device writes, mapped for
  /// reading after each pass (HostView), elsewhere device memory read back.
  cl::Buffer result_buffer(cl_mem_flags access, size_t bytes) const {
    return cl::Buffer(ctx.context, access | (map_results ? CL_MEM_ALLOC_HOST_PTR : 0), bytes);
  }

  /// Bytes of one element of the pass sums (b_sum, b_sumsq).
  size_t sum_bytes() const { return accum_double ? sizeof(cl_double4) : sizeof(cl_float4); }
  /// Component c of the last pass's sum (c = 3: accepted samples) and sum of squares of item k.
  double sum_at(size_t k, int c) const { return accum_double ? h_sum[k].s[c] : h_sum_f[k].s[c]; }
  double sumsq_at(size_t k, int c) const {
    return accum_double ? h_sumsq[k].s[c] : h_sumsq_f[k].s[c];
  }
  /// Caustics: channel c of the sum and the sum of squares of item k's light paths' totals, in a
  /// pass of `items` items (after the items' sums, megakernel.cl).
  double total_at(size_t items, size_t k, int c) const { return sum_at(items + k, c); }
  double totalsq_at(size_t items, size_t k, int c) const { return sumsq_at(items + k, c); }
  /// Bytes of one element of the light sums (b_light, b_lightsq).
  size_t light_bytes() const { return light_double ? sizeof(cl_double4) : sizeof(cl_float4); }
  /// Component c of the last pass's light sum and sum of squares of element k.
  double light_at(size_t k, int c) const {
    return light_double ? h_light[k].s[c] : h_light_f[k].s[c];
  }
  double lightsq_at(size_t k, int c) const {
    return light_double ? h_lightsq[k].s[c] : h_lightsq_f[k].s[c];
  }
  /// Drops the light sums' host views (a scene without caustics).
  void drop_light_views() {
    h_light.drop(ctx.queue);
    h_lightsq.drop(ctx.queue);
    h_light_f.drop(ctx.queue);
    h_lightsq_f.drop(ctx.queue);
  }

  size_t global_size(size_t items) const {
    const size_t g = program->work_group;
    return (items + g - 1) / g * g;
  }

  /// Makes the light buffers hold at least `elems` elements (an adaptive render's two films).
  void ensure_light(size_t elems) {
    if (light_elems >= elems) return;
    release_results();
    b_light = result_buffer(CL_MEM_READ_WRITE, elems * light_bytes());
    b_lightsq = result_buffer(CL_MEM_READ_WRITE, elems * light_bytes());
    light_elems = elems;
    set_args();
  }

  void set_args() {
    int arg = dev->set_args(program->kernel);
    program->kernel.setArg(arg++, b_work);
    program->kernel.setArg(arg++, b_sum);
    program->kernel.setArg(arg++, b_sumsq);
    program->kernel.setArg(arg++, b_counters);
    program->kernel.setArg(arg++, b_light);
    program->kernel.setArg(arg++, b_lightsq);
  }

  /// Launches samples [first, first + n) of every pixel and reads back their sums.
  void pass(const lc_params& params, std::uint64_t first, std::uint32_t n, PassCounts& counts) {
    lc_params P = params;
    P.sample_offset = static_cast<lc_uint>(first);
    P.samples_per_pass = n;
    P.work_items = 0;
    launch(P, npix, nullptr, counts);
  }

  /// Launches the work list `entries` (pixel, first sample, samples, stream; at most npix) and
  /// reads back their sums, entry by entry.
  void pass_list(const lc_params& params, const std::vector<cl_uint4>& entries,
                 PassCounts& counts) {
    lc_params P = params;
    P.work_items = static_cast<lc_uint>(entries.size());
    launch(P, entries.size(), &entries, counts);
  }

  void launch(const lc_params& P, size_t items, const std::vector<cl_uint4>* entries,
              PassCounts& counts) {
    // each count's low word starts at 0 (at counter_start() in a test, taken off again below)
    const lc_uint start = render_detail::counter_start();
    lc_uint initial[LC_COUNTER_COUNT] = {};
    initial[LC_COUNTER_NONFINITE] = initial[LC_COUNTER_RAYS] = start;
    cl::CommandQueue& q = ctx.queue;
    release_results();
    q.enqueueWriteBuffer(dev->params, CL_FALSE, 0, sizeof(P), &P);
    q.enqueueWriteBuffer(b_counters, CL_FALSE, 0, sizeof(initial), initial);
    if (entries)
      q.enqueueWriteBuffer(b_work, CL_FALSE, 0, items * sizeof(cl_uint4), entries->data());
    const bool light = P.flags & LC_FLAG_CAUSTICS;
    const size_t nl = entries ? 2 * npix : npix;  // a work list's: halves A and B
    if (light) {
      const cl_float4 z = {{0, 0, 0, 0}};  // zero bits: 0.0 in double too
      q.enqueueFillBuffer(b_light, z, 0, nl * light_bytes());
      q.enqueueFillBuffer(b_lightsq, z, 0, nl * light_bytes());
    }
    q.enqueueNDRangeKernel(program->kernel, cl::NullRange, cl::NDRange(global_size(items)),
                           cl::NDRange(program->work_group));
    const size_t ns = light ? 2 * items : items;  // and the light paths' totals
    if (accum_double) {
      h_sum.fetch(q, b_sum, ns, map_results);
      h_sumsq.fetch(q, b_sumsq, ns, map_results);
    } else {
      h_sum_f.fetch(q, b_sum, ns, map_results);
      h_sumsq_f.fetch(q, b_sumsq, ns, map_results);
    }
    if (light && light_double) {
      h_light.fetch(q, b_light, nl, map_results);
      h_lightsq.fetch(q, b_lightsq, nl, map_results);
    } else if (light) {
      h_light_f.fetch(q, b_light, nl, map_results);
      h_lightsq_f.fetch(q, b_lightsq, nl, map_results);
    }
    lc_uint c[LC_COUNTER_COUNT];
    q.enqueueReadBuffer(b_counters, CL_TRUE, 0, sizeof(c), c);
    // 64-bit counts: the high word holds the carries out of the low word (megakernel.cl)
    auto count = [&](int low, int high) { return (std::uint64_t(c[high]) << 32 | c[low]) - start; };
    counts.nonfinite = count(LC_COUNTER_NONFINITE, LC_COUNTER_NONFINITE_HIGH);
    counts.rays = count(LC_COUNTER_RAYS, LC_COUNTER_RAYS_HIGH);
  }
};

}  // namespace

SessionOptions SessionOptions::from_environment() {
  SessionOptions o;
  o.device = env_or_empty("LUCENT_DEVICE");
  o.kernel_dir = env_or_empty("LUCENT_KERNEL_DIR");
  o.cache_dir = env_or_empty("LUCENT_CACHE_DIR");
  return o;
}

struct Renderer::Impl {
  SessionOptions options;
  std::vector<std::unique_ptr<Worker>> workers;
  std::vector<DeviceInfo> device_infos;
  std::string cache_dir;

  std::optional<Scene> scene;
  bool scene_taken = false;  // set_scene(Scene&&): the application holds no copy of its own
  render_detail::PackedScene packed;  // what the device buffers hold
  /// A set_scene failed after it had begun to change the devices: their buffers match neither
  /// `packed` nor `scene`. They were dropped (the next set_scene uploads everything), and
  /// rendering is refused until a set_scene succeeds; the accumulation stays readable.
  std::string stale;
  std::string build_options;
  size_t npix = 0;

  // the accumulation
  std::vector<double> sum, sumsq;
  std::vector<std::uint32_t> count;
  std::uint64_t first = 0, done = 0, nonfinite = 0, rays = 0;
  /// The end of the sample indices accumulated: first + done, unless a pass failed while other
  /// devices' later passes were accumulated (then the samples are not one range from first). The
  /// next render starts there, so that no sample index is rendered twice.
  std::uint64_t end_index = 0;
  // caustics (docs/rendering-model.md): the light paths' sums of contributions and of their
  // squares per pixel, and the number of light paths
  std::vector<double> light_sum, light_sumsq;
  std::uint64_t light_paths = 0;
  render_detail::LightTotals light_totals;  // the light paths' totals, for the image mean
  double render_seconds = 0;
  bool last_cancelled = false;
  /// A call is in progress (RenderCall): a render (render, render_for, render_adaptive), whose
  /// on_progress may read the session (result, spp, stats) but not change it, or one that
  /// changes the session (set_scene, set_camera, reset, set_build_options)
  std::atomic<bool> rendering{false};
  /// A render call (a RenderCall of a render) is in progress: its passes run.
  std::atomic<bool> in_render{false};

  std::set<std::string> notes_given;  ///< the warnings about its scenes this session has given
  std::atomic<bool> cancel_requested{false};
  /// (atomic: set_cancel_flag and a CancelScope's end may come from another thread than a render's)
  std::atomic<const std::atomic<bool>*> cancel_flag{nullptr};
  /// render_detail::CancelScopes alive: while one is, the calls are one operation, whose cancel a
  /// call's start keeps (begin_call)
  std::atomic<int> cancel_scopes{0};
  SessionStats stats;

  explicit Impl(SessionOptions o) : options(std::move(o)) {
    // a NaN pass duration made every pass 0 samples long: render() never ended
    if (!(options.pass_seconds > 0) || !std::isfinite(options.pass_seconds))
      throw Error("SessionOptions::pass_seconds must be a positive number of seconds, got " +
                  scene_detail::format_number(options.pass_seconds));
    // (set_build_options refuses it; SessionOptions took 5 for float)
    if (options.precision != Precision::Float && options.precision != Precision::Double)
      throw Error("SessionOptions::precision must be Precision::Float or Precision::Double, got " +
                  std::to_string(static_cast<int>(options.precision)));
    const std::vector<DeviceInfo> devices = select_devices(options.device, "device");
    // double precision on a device without fp64: refused here, not at the first set_scene
    for (const DeviceInfo& d : devices)
      render_detail::check_precision_support(d, options.precision);
    for (const DeviceInfo& d : devices) {
      workers.push_back(std::make_unique<Worker>(std::to_string(d.index)));
      device_infos.push_back(workers.back()->ctx.device.info);
    }
    cache_dir = resolve_cache_dir(options.cache_dir);
  }

  bool cancelled() const {
    const std::atomic<bool>* flag = cancel_flag.load();
    return cancel_requested.load() || (flag && flag->load());
  }

  /// Refuses `call` during a render call of this session (from its on_progress callback, or
  /// another thread): set_scene there replaced the buffers and the accumulation under the passes
  /// still running (two devices: a crash in the driver; one: a render that claimed its samples
  /// and held none).
  void check_not_rendering(const char* call) const {
    cl_util::check_not_forked();  // (a session made before a fork: its calls would hang)
    if (rendering.load()) throw rendering_error(call);
  }
  Error rendering_error(const char* call) const {
    if (const char* by = held_by.load())
      return Error(std::string(call) + ": cannot change the session while " + by +
                   " runs, which holds it (it may read result(), spp() and stats(), or "
                   "cancel())");
    return Error(std::string(call) +
                 ": a render of this session is in progress, or another call that changes it "
                 "(a session runs one call at a time; a render's on_progress may read result(), "
                 "spp() and stats(), or cancel())");
  }
  /// What holds the session outside a call (CancelScope::hold: run_convergence's on_point),
  /// for the refusal's message; null otherwise.
  std::atomic<const char*> held_by{nullptr};
  /// Marks a call in progress while it lives, a render or one that changes the session
  /// (set_scene, set_camera, reset, set_build_options), and refuses another: set_scene from
  /// another thread passed check_not_rendering just before a render began, and replaced its
  /// buffers under it (SIGSEGV).
  struct RenderCall {
    Impl& s;
    /// `render`: a render call (passes run: in_render), not one that changes the session.
    RenderCall(Impl& impl, const char* call, bool render = false) : s(impl) {
      cl_util::check_not_forked();
      if (s.rendering.exchange(true)) throw s.rendering_error(call);
      s.in_render = render;
      // a cancel of an earlier render is dropped here too, as a render's begin_call drops it: a
      // set_scene that met another process's build lock after a cancelled render gave up its
      // wait at once ("kernel build cancelled")
      if (!render && s.cancel_scopes == 0) s.cancel_requested = false;
    }
    ~RenderCall() {
      s.in_render = false;
      s.rendering = false;
    }
    RenderCall(const RenderCall&) = delete;
    RenderCall& operator=(const RenderCall&) = delete;
  };

  void clear_accumulation(std::uint64_t first_sample) {
    std::fill(sum.begin(), sum.end(), 0.0);
    std::fill(sumsq.begin(), sumsq.end(), 0.0);
    std::fill(count.begin(), count.end(), 0u);
    std::fill(light_sum.begin(), light_sum.end(), 0.0);
    std::fill(light_sumsq.begin(), light_sumsq.end(), 0.0);
    light_paths = 0;
    light_totals = {};
    first = first_sample;
    done = nonfinite = rays = 0;
    end_index = first_sample;
    render_seconds = 0;
    last_cancelled = false;
    for (auto& w : workers) w->share.samples = w->share_samples = 0, w->share.seconds = 0;
    clear_adaptive();
  }

  /// The worker's program for these build options, built (or loaded from the cache) or reused.
  /// A new build's cache entry is left in `entry`, to be stored after the warm-up launch; no entry
  /// on PoCL (cl/program_cache.hpp, keeps_program_binaries).
  Program& get_program(Worker& w, const std::string& opts, const std::string& source,
                       cl_util::DeferredEntry& entry) {
    auto it = w.programs.find(opts);
    if (it != w.programs.end()) return it->second;
    auto t0 = clock_type::now();
    cl_util::ProgramBuildInfo info;
    Program p;
    try {
      const bool entries = cl_util::keeps_program_binaries(w.ctx.device);
      // without entries the directory serves the build locks, so that processes building one
      // program together build it once: worth it where the driver's cache then serves the
      // others, not on PoCL with its cache off, where they waited to build it again each (the
      // review's find)
      const bool locks = entries || !cl_util::driver_program_cache(w.ctx.device).empty();
      p.program = cl_util::build_program_cached(
          w.ctx, source, opts + render_detail::device_defines(w.ctx.device.info),
          locks ? cache_dir : std::string(), &info, &entry, entries,
          [this] { return cancelled(); });
    } catch (const Error& e) {
      // the place of a build error is "kernels/<file>:<line>": the file in the kernel directory
      // in use when the sources came from one
      const std::string what = e.what();
      if (options.kernel_dir.empty() || what.rfind("kernels/", 0) != 0) throw;
      throw Error(options.kernel_dir + what.substr(7), e.details());
    }
    try {
      p.kernel = cl::Kernel(p.program, "lucent_render");
    } catch (const cl::Error& e) {
      // a program the driver's cache gave back damaged (PoCL's, after a power loss: an empty
      // program.bc) has no kernel: the error named neither the cache nor the remedy
      const std::string driver_cache = cl_util::driver_program_cache(w.ctx.device);
      if (e.err() != CL_INVALID_KERNEL_NAME || driver_cache.empty()) throw;
      throw Error(std::string("clCreateKernel: ") + cl_util::error_name(e.err()) +
                  ": the program " + driver_cache + " gave back has no kernel: that cache, in " +
                  cl_util::pocl_cache_dir() + ", may be damaged; remove the directory");
    }
    p.work_group = render_detail::work_group_size(
        kWorkGroupSize, w.ctx.device.device.getInfo<CL_DEVICE_MAX_WORK_GROUP_SIZE>(),
        w.ctx.device.device.getInfo<CL_DEVICE_MAX_WORK_ITEM_SIZES>().at(0),
        p.kernel.getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(w.ctx.device.device));
    p.cache_hit = info.cache_hit;
    // the source this program was built from: a kernel directory's files may have changed since
    // the session's first build (one that failed, then fixed: the first source's hash was kept)
    p.source_hash = fnv1a(source.data(), source.size());
    if (!info.note.empty()) scene_detail::warn(info.note);
    if (info.cache_hit)
      ++stats.kernel_cache_loads;
    else
      ++stats.kernel_compiles;
    p.build_seconds = seconds_since(t0);
    stats.build_seconds += p.build_seconds;
    return w.programs.emplace(opts, std::move(p)).first->second;
  }

  /// A launch without samples: some drivers (PoCL) compile the work-group function at the first
  /// enqueue; it counts as build time, not render time.
  void warm_up(Worker& w) {
    auto t0 = clock_type::now();
    lc_params P0 = packed.params;
    P0.samples_per_pass = 0;
    w.ctx.queue.enqueueWriteBuffer(w.dev->params, CL_FALSE, 0, sizeof(P0), &P0);
    w.ctx.queue.enqueueNDRangeKernel(w.program->kernel, cl::NullRange,
                                     cl::NDRange(w.global_size(w.npix)),
                                     cl::NDRange(w.program->work_group));
    w.ctx.queue.finish();
    double s = seconds_since(t0);
    w.program->build_seconds += s;
    stats.build_seconds += s;
  }

  /// After a set_scene that failed part-way (`what`): every device drops its scene and film
  /// buffers, whatever they held, so that the next set_scene uploads everything (packed no
  /// longer tells what they hold) and nothing renders from them meanwhile.
  void drop_device_scenes(const std::string& what) {
    for (auto& w : workers) {
      w->dev.reset();
      w->npix = 0;
      w->b_sum = cl::Buffer();
    }
    stale = what;
  }
  void check_not_stale(const char* call) const {
    if (!stale.empty())
      throw Error(std::string(call) +
                  ": the last set_scene failed, so the devices hold no scene (call set_scene "
                  "again; result() still has what was rendered before): " +
                  stale);
  }

  /// What a set_scene or set_camera call is warned of (validation, energy, packing, precision),
  /// collected while it runs (collect(), the sink of a ScopedWarningSink), then given on, each
  /// once per session: an AOV render, a converge study's settings and an application's camera
  /// moves set the scene again (a render with 3 AOVs said each 4 times).
  class CallNotes {
   public:
    explicit CallNotes(std::set<std::string>& given) : given_(given) {}
    CallNotes(const CallNotes&) = delete;
    CallNotes& operator=(const CallNotes&) = delete;
    const std::function<void(const std::string&)>& collect() const { return collect_; }
    void give() const {
      // a note counts as given once the sink took it: one that throws (an application that
      // makes warnings errors) fails the call, and the same scene set again was accepted
      // without a word
      for (const std::string& note : notes_)
        if (given_.count(note) == 0) {
          scene_detail::warn(note);
          given_.insert(note);
        }
    }

   private:
    std::set<std::string>& given_;
    std::vector<std::string> notes_;
    const std::function<void(const std::string&)> collect_ = [this](const std::string& m) {
      notes_.push_back(m);
    };
  };

  /// `take`, when not null, is `s` itself, given to the session (moved in on success) instead
  /// of copied.
  void set_scene(const Scene& s, Scene* take = nullptr) {
    scene_detail::ScopedWarningSink sink(options.on_warning);
    CallNotes notes(notes_given);
    std::vector<render_detail::DeviceLimits> limits;
    auto t0 = clock_type::now();
    bool bvh_reused = false;
    const bool uploaded = workers.front()->dev.has_value();
    render_detail::PackedScene next;
    try {
      scene_detail::ScopedWarningSink capture(notes.collect());
      scene_detail::validate_scene(s);  // fields set directly may not have been checked
      for (const std::string& note : scene_detail::energy_gain_notes(s)) scene_detail::warn(note);
      for (auto& w : workers) limits.push_back(render_detail::DeviceLimits::of(w->ctx.device));
      render_detail::check_host_memory(
          s, limits, limits.front().host_mem, limits.front().host_what,
          render_detail::reserved_part(options.reserved_host_bytes, options.reserved_host_what),
          take ? 1 : 2);
      for (const DeviceInfo& d : device_infos)
        render_detail::check_precision_support(d, options.precision);
      t0 = clock_type::now();
      next = render_detail::pack_scene(s, uploaded ? &packed : nullptr, &bvh_reused);
      for (const std::string& note :
           render_detail::packing_notes(s, next, options.precision == Precision::Float))
        scene_detail::warn(note);
    } catch (...) {
      notes.give();
      throw;
    }
    notes.give();
    ++stats.scene_packs;
    if (!bvh_reused) {
      ++stats.bvh_builds;
      stats.bvh_seconds += next.bvh_stats.seconds;
    }
    stats.pack_seconds += seconds_since(t0);
    RenderOptions ro;
    ro.precision = options.precision;
    ro.fast_math = options.fast_math;
    ro.specialize = options.specialize;
    std::string opts = render_detail::build_options(s, next, ro);

    const bool keep = uploaded && opts == build_options && same_render_data(packed, next);
    const size_t n = static_cast<size_t>(s.film.width) * s.film.height;
    for (const render_detail::DeviceLimits& l : limits)
      render_detail::check_device_memory(s, next, l);
    // which buffers differ from what the devices hold, compared once for all of them
    const unsigned changes = uploaded ? render_detail::scene_changes(packed, next) : ~0u;
    std::string device;  // the one being set up, and what it does, for messages
    render_detail::ClStage stage = render_detail::ClStage::Upload;
    bool touched = false;
    bool built = false;  // a device built (or loaded) a program: the call did not keep it
    try {
      std::string source;
      for (auto& wp : workers) {
        Worker& w = *wp;
        device = w.ctx.device.info.name;
        stage = render_detail::ClStage::Upload;
        Program* previous_program = w.program;
        if (!w.programs.count(opts) && source.empty()) {
          source = detail::assemble_kernel_source("megakernel.cl", options.kernel_dir);
        }
        cl_util::DeferredEntry entry;
        if (!w.programs.count(opts)) built = true;
        w.program = &get_program(w, opts, source, entry);
        touched = true;  // from here on a failure leaves the devices' buffers in doubt
        if (!w.dev) {
          w.dev.emplace(w.ctx, next);
          // every buffer that holds data was written (an empty one is created without any, as
          // update() does not count an empty buffer that stays empty)
#define LUCENT_BYTES(name, type, ...)                        \
  if (!next.name.empty()) {                                  \
    ++stats.buffer_uploads;                                  \
    stats.bytes_uploaded += next.name.size() * sizeof(type); \
  }
          LC_SCENE_BUFFERS(LUCENT_BYTES)
#undef LUCENT_BYTES
        } else {
          render_detail::DeviceScene::Upload up = w.dev->update(w.ctx, changes, next);
          stats.buffer_uploads += up.buffers;
          stats.bytes_uploaded += up.bytes;
        }
        if (render_detail::upload_fault())
          throw cl::Error(CL_MEM_OBJECT_ALLOCATION_FAILURE, "clCreateBuffer (injected by a test)");
        // the light sums take a film's worth of memory only when the kernel traces light paths
        const bool light = next.params.flags & LC_FLAG_CAUSTICS;
        if (n != w.npix || !w.b_sum() || light != w.light_buffers) {
          w.release_results();
          w.npix = n;
          w.b_work = cl::Buffer(w.ctx.context, CL_MEM_READ_ONLY, n * sizeof(cl_uint4));
          // with caustics the light paths' totals follow the items' sums (megakernel.cl)
          const size_t ns = light ? 2 * n : n;
          w.b_sum = w.result_buffer(CL_MEM_WRITE_ONLY, ns * w.sum_bytes());
          w.b_sumsq = w.result_buffer(CL_MEM_WRITE_ONLY, ns * w.sum_bytes());
          w.b_counters =
              cl::Buffer(w.ctx.context, CL_MEM_READ_WRITE, LC_COUNTER_COUNT * sizeof(lc_uint));
          const size_t nl = light ? n : 1;  // an adaptive render doubles it (ensure_light)
          w.b_light = w.result_buffer(CL_MEM_READ_WRITE, nl * w.light_bytes());
          w.b_lightsq = w.result_buffer(CL_MEM_READ_WRITE, nl * w.light_bytes());
          w.light_buffers = light;
          w.light_elems = nl;
          if (!light) w.drop_light_views();
        }
        w.set_args();
        if (w.program != previous_program) {
          packed.params = next.params;  // the warm-up launch's parameters
          stage = render_detail::ClStage::Pass;
          warm_up(w);
        }
        if (entry.pending()) {
          // after the warm-up, so that the entry holds the work-group function the driver
          // compiled at that launch (a hit then launches at once); a driver that caches its own
          // builds (PoCL) has had them cached under the lock
          auto t0 = clock_type::now();
          entry.store(w.program->program);
          const double s = seconds_since(t0);
          w.program->build_seconds += s;
          stats.build_seconds += s;
        }
      }
    } catch (const cl::Error& e) {
      const std::string what = render_detail::resource_error(e, stage, s.path, device);
      if (touched) drop_device_scenes(what);
      throw Error(what);
    } catch (const std::exception& e) {
      if (touched) drop_device_scenes(e.what());
      throw;
    }
    if (!built) ++stats.kernel_reuses;  // once per call, whatever the number of devices
    stale.clear();
    // the arrays that did not change keep the storage that the CPU devices' buffers share (the
    // others' buffers were made over next's): the scene's arrays are held once
    if (uploaded) render_detail::keep_unchanged_storage(packed, next, changes);
    packed = std::move(next);
    build_options = opts;
    npix = n;
    if (take)
      scene = std::move(*take);
    else
      scene = s;
    scene_taken = take != nullptr;
    sys::return_free_memory();  // the BVH build's and the previous scene's arrays
    if (!keep) {
      sum.assign(npix * 3, 0.0);
      sumsq.assign(npix * 3, 0.0);
      count.assign(npix, 0u);
      const bool caustics = packed.params.flags & LC_FLAG_CAUSTICS;
      light_sum.assign(caustics ? npix * 3 : 0, 0.0);
      light_sumsq.assign(caustics ? npix * 3 : 0, 0.0);
      clear_accumulation(first);
      for (auto& w : workers) w->pass_spp = 1;
    }
  }

  /// Renderer::set_camera: set_scene() of the session's scene with `camera`, without packing it
  /// again where only the launch parameters (and the light table an environment light weighs by
  /// the camera) change. Nothing of the session changes before the camera passed the checks.
  void set_camera(const Camera& camera) {
    if (!scene) throw Error("set_camera: the session has no scene (call set_scene first)");
    scene_detail::ScopedWarningSink sink(options.on_warning);
    CallNotes notes(notes_given);  // the session's warnings, each once, as set_scene gives them
    {
      scene_detail::ScopedWarningSink capture(notes.collect());
      try {
        // set_scene's check of the camera, at its place in the scene ("scene.json: /camera/fov:
        // ..."); the rest of the scene passed it when it was set
        scene_detail::validate_camera(camera, scene_detail::Reporter(scene->path, "/camera"));
      } catch (...) {
        notes.give();
        throw;
      }
    }
    // the kernel's build options with the new camera, where the camera can change them (an
    // aperture from or to 0: the lens code); read with the camera put in the held scene for the
    // call, which changes nothing else. (Reading them for every move scanned the packing's
    // triangles: 7 ms of a 7 ms move on 10^6 triangles.)
    std::string opts = build_options;
    if (render_detail::camera_features_differ(scene->camera, camera)) {
      RenderOptions ro;
      ro.precision = options.precision;
      ro.fast_math = options.fast_math;
      ro.specialize = options.specialize;
      const Camera kept = scene->camera;
      scene->camera = camera;
      try {
        opts = render_detail::build_options(*scene, packed, ro);
      } catch (...) {
        scene->camera = kept;
        throw;
      }
      scene->camera = kept;
    }
    if (!stale.empty() || opts != build_options) {
      // another kernel, or devices that hold no scene since a set_scene failed: the whole
      // set_scene, of the held scene moved out and back (not copied: a large mesh is held once)
      Scene s = std::move(*scene);
      const Camera kept = s.camera;
      const bool taken = scene_taken;
      s.camera = camera;
      try {
        set_scene(s, &s);
      } catch (...) {
        s.camera = kept;  // set_scene left `s` as it was
        scene = std::move(s);
        throw;
      }
      scene_taken = taken;
      return;
    }
    render_detail::CameraPacking next;
    {
      scene_detail::ScopedWarningSink capture(notes.collect());
      try {
        next = render_detail::repack_camera(*scene, packed, camera);
      } catch (...) {
        notes.give();
        throw;
      }
    }
    notes.give();
    const bool keep =
        !next.lights_changed && std::memcmp(&next.params, &packed.params, sizeof(lc_params)) == 0;
    if (next.lights_changed) {
      // the array that did not change keeps its storage, which the CPU devices' buffers share
      const unsigned changes = render_detail::light_changes(packed, next.lights, next.light_cdf);
      std::string device;
      try {
        for (auto& w : workers) {
          device = w->ctx.device.info.name;
          const render_detail::DeviceScene::Upload up =
              w->dev->update_lights(w->ctx, changes, next.lights, next.light_cdf);
          stats.buffer_uploads += up.buffers;
          stats.bytes_uploaded += up.bytes;
          if (render_detail::upload_fault())
            throw cl::Error(CL_MEM_OBJECT_ALLOCATION_FAILURE,
                            "clCreateBuffer (injected by a test)");
          w->set_args();  // a buffer may have been made again
        }
      } catch (const cl::Error& e) {
        const std::string what =
            render_detail::resource_error(e, render_detail::ClStage::Upload, scene->path, device);
        drop_device_scenes(what);
        throw Error(what);
      } catch (const std::exception& e) {
        drop_device_scenes(e.what());
        throw;
      }
      if (changes & render_detail::kBufferBit(render_detail::lights_index))
        packed.lights = std::move(next.lights);
      if (changes & render_detail::kBufferBit(render_detail::light_cdf_index))
        packed.light_cdf = std::move(next.light_cdf);
    }
    // the launch parameters go to the devices with each pass (Worker::launch)
    packed.params = next.params;
    scene->camera = camera;
    ++stats.camera_moves;
    if (!keep) {
      clear_accumulation(first);
      for (auto& w : workers) w->pass_spp = 1;
    }
  }

  /// Adds one pass's sums to the accumulation.
  void accumulate(const Worker& w, std::uint32_t n) {
    for (size_t i = 0; i < npix; ++i) {
      for (int c = 0; c < 3; ++c) {
        sum[i * 3 + c] += w.sum_at(i, c);
        sumsq[i * 3 + c] += w.sumsq_at(i, c);
      }
      count[i] += static_cast<std::uint32_t>(w.sum_at(i, 3));
    }
    if (!light_sum.empty()) {
      for (size_t i = 0; i < npix; ++i)
        for (int c = 0; c < 3; ++c) {
          light_sum[i * 3 + c] += w.light_at(i, c);
          light_sumsq[i * 3 + c] += w.lightsq_at(i, c);
          light_totals.sum[c] += w.total_at(npix, i, c);
          light_totals.sumsq[c] += w.totalsq_at(npix, i, c);
        }
      light_paths += std::uint64_t(n) * npix;
    }
    done += n;
  }

  /// The next pass size of a worker whose last pass of `spp` samples per pixel (or their
  /// equivalent in a work list's samples) took pass_time seconds: aim at pass_seconds per
  /// launch, within the time left.
  void tune(Worker& w, double spp, double pass_time, double time_left) {
    double per_spp = pass_time / spp;
    double want = per_spp > 0 ? options.pass_seconds / per_spp : 2.0 * spp;
    w.pass_spp = static_cast<std::uint32_t>(
        std::clamp(want, 1.0, std::min(4.0 * std::max(1.0, spp), 65536.0)));
    if (time_left < std::numeric_limits<double>::infinity() && per_spp > 0)
      w.pass_spp =
          static_cast<std::uint32_t>(std::clamp(time_left / per_spp, 1.0, double(w.pass_spp)));
  }

  /// One launch: samples [begin, begin + n) of every pixel, or a slice of a work list.
  struct Job {
    std::uint64_t begin = 0;
    std::uint32_t n = 0;
    std::vector<cl_uint4> entries;  // a work list instead (n: 0)
    double spp = 0;                 // its samples per pixel, or their equivalent, for tuning
  };

  /// Launches jobs on every device until `next` has none (or the time limit, a cancel or an
  /// error), with the accumulation and the call's statistics guarded by one lock. `next(w, job)`
  /// (under the lock) fills the worker's next job or returns false; `finish(w, job)`
  /// (under the lock) takes its results. At least one job runs unless cancelled with samples
  /// already accumulated.
  struct CallState {
    std::mutex m;
    clock_type::time_point t_start = clock_type::now();
    double call_seconds = 0;  // kernel time, summed over devices
    bool started = false;     // a job of this call was launched
  };
  /// The start of a render call: no cancel pending (but one asked for during a CancelScope's
  /// operation), the call's shares at zero.
  void begin_call() {
    if (cancel_scopes == 0) cancel_requested = false;
    last_cancelled = false;
    for (auto& w : workers) w->call.samples = w->call_samples = 0, w->call.seconds = 0;
  }
  void dispatch(CallState& cs, double time_limit, bool have_samples,
                const std::function<bool(Worker&, Job&)>& next,
                const std::function<void(Worker&, const Job&)>& finish,
                const std::function<void()>& on_pass) {
    bool& started = cs.started;
    std::exception_ptr failure;
    // the call's time is up (a call that has launched nothing yet launches a job)
    auto out_of_time = [&] {
      return time_limit > 0 && started && seconds_since(cs.t_start) >= time_limit;
    };
    // With several devices each takes its first job before any takes a second: a device whose
    // thread starts late still gets its share (the others do not drain a short render first).
    // Not once the time is up: an adaptive render dispatches round after round in one call, and
    // each round after the limit ran one more pass on every device.
    std::vector<Job> first_job(workers.size());
    std::vector<char> has_first(workers.size(), 0);
    if (workers.size() > 1 && !cancelled() && !out_of_time())
      for (size_t i = 0; i < workers.size(); ++i)
        if (next(*workers[i], first_job[i])) has_first[i] = 1, started = true;
    auto work = [&](Worker& w, size_t index) {
      try {
        for (bool first = true;; first = false) {
          Job job;
          if (first && has_first[index]) {
            job = std::move(first_job[index]);
          } else {
            std::lock_guard<std::mutex> lock(cs.m);
            if (failure) return;
            if (out_of_time()) return;
            if (cancelled() && (have_samples || started)) {
              last_cancelled = true;
              return;
            }
            if (!next(w, job)) return;
            started = true;
          }
          if (render_detail::pass_fault(job.begin))
            throw cl::Error(CL_OUT_OF_RESOURCES, "clEnqueueNDRangeKernel (injected by a test)");
          PassCounts counts;
          auto tp = clock_type::now();
          lc_params P = packed.params;
          if (unsplit_passes) P.splits = 0;  // an adaptive pilot (run_adaptive)
          if (job.entries.empty())
            w.pass(P, job.begin, job.n, counts);
          else
            w.pass_list(P, job.entries, counts);
          double pass_time = seconds_since(tp);
          std::lock_guard<std::mutex> lock(cs.m);
          finish(w, job);
          nonfinite += counts.nonfinite;
          rays += counts.rays;
          cs.call_seconds += pass_time;
          render_seconds += pass_time;
          stats.render_seconds += pass_time;
          ++stats.passes;
          w.call.seconds += pass_time;
          w.share.seconds += pass_time;
          double left = time_limit > 0 ? time_limit - seconds_since(cs.t_start)
                                       : std::numeric_limits<double>::infinity();
          tune(w, job.spp, pass_time, left);
          if (on_pass) on_pass();
        }
      } catch (const cl::Error& e) {
        std::lock_guard<std::mutex> lock(cs.m);
        if (!failure)
          failure = std::make_exception_ptr(Error(render_detail::resource_error(
              e, render_detail::ClStage::Pass, scene->path, w.ctx.device.info.name)));
      } catch (...) {
        std::lock_guard<std::mutex> lock(cs.m);
        if (!failure) failure = std::current_exception();
      }
    };
    if (workers.size() == 1) {
      work(*workers.front(), 0);
    } else {
      std::vector<std::thread> threads;
      for (size_t i = 0; i < workers.size(); ++i)
        threads.emplace_back(work, std::ref(*workers[i]), i);
      for (auto& t : threads) t.join();
    }
    if (failure) std::rethrow_exception(failure);
  }

  RenderProgress make_progress(const CallState& cs, std::uint64_t finished, std::uint64_t target,
                               double time_limit) const {
    RenderProgress pr;
    pr.samples_done = finished;
    pr.samples_target = target;
    pr.accumulated = done;
    pr.elapsed = seconds_since(cs.t_start);
    pr.time_limit = time_limit;
    pr.samples_per_second = pr.elapsed > 0 ? double(finished) * npix / pr.elapsed : 0;
    if (workers.size() == 1)
      pr.samples_per_second = cs.call_seconds > 0 ? double(finished) * npix / cs.call_seconds : 0;
    for (auto& w : workers) pr.devices.push_back(w->call);
    return pr;
  }

  /// Adds samples until `target_spp` more (0: no limit) or `time_limit` seconds (0: none), at
  /// least one pass unless cancelled with samples already accumulated. With several devices,
  /// each takes the next range of sample indices when its pass is done.
  RenderProgress run(std::uint64_t target_spp, double time_limit,
                     const std::function<void(const RenderProgress&)>& on_progress) {
    RenderCall call(*this, "render", true);
    if (!scene) throw Error("render: the session has no scene (call set_scene first)");
    check_not_stale("render");
    if (adaptive)
      throw Error("render: the accumulation is an adaptive render's (call reset() first)");
    begin_call();
    CallState cs;
    std::uint64_t started = 0, finished = 0;  // samples per pixel of this call
    const std::uint64_t start_index = end_index;
    // the sampler takes 32-bit sample indices: past 2^32 samples would repeat
    const std::uint64_t index_end = std::uint64_t(1) << 32;
    if (start_index >= index_end || (target_spp > 0 && target_spp > index_end - start_index))
      throw Error("render: " + std::to_string(target_spp > 0 ? target_spp : 1) +
                  " samples from sample index " + std::to_string(start_index) +
                  " go past 2^32, the sampler's range (samples would repeat)");
    // the per-pixel counts are 32-bit: an accumulation holds at most 2^32 - 1 samples per pixel
    // (all of [0, 2^32) wrapped every count to 0: pixels without samples, a black image)
    const std::uint64_t count_max = 0xffffffffull;
    if (done >= count_max || (target_spp > 0 && target_spp > count_max - done))
      throw Error("render: " + std::to_string(target_spp > 0 ? target_spp : 1) +
                  " samples per pixel on top of the accumulation's " + std::to_string(done) +
                  " exceed 2^32 - 1, the most a pixel's sample count holds");
    // the samples this call may launch: a time-limited render stops at either limit
    const std::uint64_t room = std::min(index_end - start_index, count_max - done);
    auto next = [&](Worker& w, Job& job) {
      if (target_spp > 0 && started >= target_spp) return false;
      if (started >= room) return false;
      job.n = static_cast<std::uint32_t>(std::min<std::uint64_t>(w.pass_spp, room - started));
      if (target_spp > 0)
        job.n = static_cast<std::uint32_t>(std::min<std::uint64_t>(job.n, target_spp - started));
      job.begin = start_index + started;
      job.spp = job.n;
      started += job.n;
      return true;
    };
    auto finish = [&](Worker& w, const Job& job) {
      accumulate(w, job.n);
      end_index = std::max(end_index, job.begin + job.n);
      finished += job.n;
      w.call.samples += job.n;
      w.share.samples += job.n;
    };
    auto on_pass = [&] {
      if (on_progress) on_progress(make_progress(cs, finished, target_spp, time_limit));
    };
    dispatch(cs, time_limit, done > 0, next, finish, on_pass);
    // a cancel once every sample was rendered (from the last pass's callback) cut nothing short
    if (target_spp > 0 && finished >= target_spp) last_cancelled = false;
    // a time-limited render that the samples' range stopped, before its time (render_for from
    // sample 2^32 - 3 returned after 3 samples without a word)
    if (target_spp == 0 && started >= room && !last_cancelled) {
      scene_detail::ScopedWarningSink sink(options.on_warning);
      scene_detail::warn("render: stopped at sample index " + std::to_string(start_index + room) +
                         " before the time limit: " +
                         (room == index_end - start_index
                              ? std::string("2^32 is the sampler's range")
                              : std::string("2^32 - 1 samples per pixel is the most a pixel's "
                                            "count holds")));
    }
    return make_progress(cs, finished, target_spp, time_limit);
  }

  // ---- adaptive renders (render_adaptive; the arithmetic is in render/adaptive.cpp) ----------

  /// One half of an adaptive render: stream `h` (seed lc_stream_seed(seed, h)), its per-pixel
  /// sums, the samples launched (sample indices first .. first + launched - 1) and planned, and
  /// what the plans read of its pilot (render_detail::Pilot: the relative variances, which plan
  /// the other half, and the sums on calib_pixels, which calibrate the other half's plan).
  struct Half {
    std::vector<double> sum, sumsq;
    std::vector<std::uint32_t> count, launched, plan;
    // caustics (A and B only): the half's light paths' splat sums and their number
    std::vector<double> light_sum, light_sumsq;
    std::uint64_t light_paths = 0;
    render_detail::LightTotals light_totals;
    render_detail::Pilot pilot;
    bool piloted = false;
  };
  bool adaptive = false;
  bool unsplit_passes = false;  // passes render without glass splitting (an adaptive pilot)
  std::uint32_t pilot = 0;      // per pixel and half
  /// A and B, then C: stream 2, the calibration's pilot (render_detail::calibrate_model) on
  /// calib_pixels only, never averaged into the image; its vectors stay empty until a render with
  /// a target needs it (a budget's plan has no use for the model's scale).
  Half halves[3];
  std::vector<std::size_t> calib_pixels;
  bool calibrated = false;              // calib holds a target render's calibration
  render_detail::Calibration calib[2];  // calib[h]: the gain of half h's plan
  double planned_relmse[2] = {0, 0};    // the calibrated plans' predictions (target renders)
  double adaptive_target = 0;
  bool pilot_done = false;  // the last call's pilot was complete (its plans were made)

  void clear_adaptive() {
    adaptive = false;
    pilot = 0;
    adaptive_target = 0;
    pilot_done = false;
    for (Half& h : halves) h = Half{};
    calib_pixels.clear();
    calibrated = false;
    calib[0] = calib[1] = render_detail::Calibration{};
    planned_relmse[0] = planned_relmse[1] = 0;
  }

  /// The sums (3 channels) and counts of `h` on the calibration pixels, in their order.
  /// With `value` (3 per pixel: a half's neighbour_values), its values there too.
  void calibration_sums(const Half& h, render_detail::Pilot& p,
                        const std::vector<double>* value = nullptr) const {
    p.sum.clear();
    p.sumsq.clear();
    p.count.clear();
    p.value.clear();
    p.pixels = calib_pixels;
    for (std::size_t i : calib_pixels) {
      for (int c = 0; c < 3; ++c) {
        p.sum.push_back(h.sum[i * 3 + c]);
        p.sumsq.push_back(h.sumsq[i * 3 + c]);
        if (value) p.value.push_back((*value)[i * 3 + c]);
      }
      p.count.push_back(h.count[i]);
    }
  }

  /// Renders every (half, pixel) up to its plan, in rounds: each round gives every entry still
  /// short of its plan up to `cap` samples, cap spreading one pass per device over the entries.
  /// Returns false when stopped by the time limit or a cancel.
  bool render_plans(CallState& cs, double time_limit, std::uint64_t& launched_total,
                    std::uint64_t call_start, std::uint64_t planned_total,
                    const std::function<void(const RenderProgress&)>& on_progress) {
    for (;;) {
      std::vector<cl_uint4> list;
      double pass_samples = 0;
      for (auto& w : workers) pass_samples += double(w->pass_spp) * double(npix);
      size_t active = 0;
      for (const Half& h : halves)
        for (size_t i = 0; i < h.plan.size(); ++i) active += h.launched[i] < h.plan[i];
      if (active == 0) return true;
      const std::uint32_t cap = static_cast<std::uint32_t>(
          std::clamp(std::ceil(pass_samples / double(active)), 1.0, 65536.0));
      list.reserve(active);
      for (lc_uint hi = 0; hi < 3; ++hi) {
        const Half& h = halves[hi];
        for (size_t i = 0; i < h.plan.size(); ++i)
          if (h.launched[i] < h.plan[i]) {
            cl_uint4 e;
            e.s[0] = static_cast<cl_uint>(i);
            e.s[1] = static_cast<cl_uint>(first + h.launched[i]);
            e.s[2] = std::min(h.plan[i] - h.launched[i], cap);
            e.s[3] = hi;
            list.push_back(e);
          }
      }
      size_t pos = 0;
      auto next = [&](Worker& w, Job& job) {
        if (pos >= list.size()) return false;
        // about one pass of this device's size, at most npix entries
        const double want = double(w.pass_spp) * double(npix);
        double samples = 0;
        size_t end = pos;
        while (end < list.size() && end - pos < npix && samples < want) samples += list[end++].s[2];
        job.entries.assign(list.begin() + pos, list.begin() + end);
        job.spp = samples / double(npix);
        pos = end;
        return true;
      };
      auto finish = [&](Worker& w, const Job& job) {
        std::uint64_t samples = 0;
        for (size_t k = 0; k < job.entries.size(); ++k) {
          const cl_uint4& e = job.entries[k];
          Half& h = halves[e.s[3]];
          const size_t i = e.s[0];
          for (int c = 0; c < 3; ++c) {
            h.sum[i * 3 + c] += w.sum_at(k, c);
            h.sumsq[i * 3 + c] += w.sumsq_at(k, c);
          }
          h.count[i] += static_cast<std::uint32_t>(w.sum_at(k, 3));
          h.launched[i] += e.s[2];
          if (!h.light_sum.empty()) {
            h.light_paths += e.s[2];  // one per camera sample
            for (int c = 0; c < 3; ++c) {
              h.light_totals.sum[c] += w.total_at(job.entries.size(), k, c);
              h.light_totals.sumsq[c] += w.totalsq_at(job.entries.size(), k, c);
            }
          }
          samples += e.s[2];
        }
        for (int hi = 0; hi < 2; ++hi) {  // the halves' light splats, anywhere on the film
          Half& h = halves[hi];
          if (h.light_sum.empty()) continue;
          for (size_t i = 0; i < npix; ++i)
            for (int c = 0; c < 3; ++c) {
              h.light_sum[i * 3 + c] += w.light_at(hi * npix + i, c);
              h.light_sumsq[i * 3 + c] += w.lightsq_at(hi * npix + i, c);
            }
        }
        launched_total += samples;
        done = (launched_total + npix / 2) / npix;
        w.call_samples += samples;
        w.share_samples += samples;
        w.call.samples = (w.call_samples + npix / 2) / npix;  // rounded as `done` is
        w.share.samples = (w.share_samples + npix / 2) / npix;
      };
      auto on_pass = [&] {
        if (on_progress)
          on_progress(make_progress(cs, (launched_total - call_start) / npix,
                                    (planned_total - call_start) / npix, time_limit));
      };
      dispatch(cs, time_limit, true, next, finish, on_pass);
      if (pos < list.size() || last_cancelled) return false;  // stopped by the clock or a cancel
    }
  }

  RenderProgress run_adaptive(const AdaptiveOptions& o,
                              const std::function<void(const RenderProgress&)>& on_progress) {
    RenderCall call(*this, "render_adaptive", true);
    if (!scene) throw Error("render_adaptive: the session has no scene (call set_scene first)");
    check_not_stale("render_adaptive");
    if (!(o.target_error > 0) == !(o.budget_spp > 0) || !std::isfinite(o.target_error) ||
        !std::isfinite(o.budget_spp))
      throw Error("render_adaptive: give either a target error or a budget, a positive number");
    // the pilot is split into two halves of (min_spp + 1) / 2 samples: an odd min_spp is
    // rounded up, and max_spp must hold that (min_spp 5 and max_spp 5 rendered 6)
    const std::uint64_t pilot_spp = 2 * ((std::uint64_t(o.min_spp) + 1) / 2);
    if (o.min_spp < 4 || o.max_spp < pilot_spp)
      throw Error(
          "render_adaptive: expected 4 <= min_spp and its pilot (min_spp rounded up to "
          "even, " +
          std::to_string(pilot_spp) + ") <= max_spp, got " + std::to_string(o.min_spp) + " and " +
          std::to_string(o.max_spp));
    if (!(o.max_seconds >= 0) || !std::isfinite(o.max_seconds))
      throw Error("render_adaptive: the time limit must be a non-negative number of seconds");
    const std::uint32_t m = (o.min_spp + 1) / 2;
    if (!adaptive) {
      if (done > 0)
        throw Error(
            "render_adaptive: the accumulation holds a uniform render's samples (call reset() "
            "first)");
      std::vector<render_detail::DeviceLimits> limits;
      for (auto& w : workers) limits.push_back(render_detail::DeviceLimits::of(w->ctx.device));
      render_detail::check_adaptive_host_memory(
          *scene, limits, (packed.params.flags & LC_FLAG_CAUSTICS) != 0, limits.front().host_mem,
          limits.front().host_what,
          render_detail::reserved_part(options.reserved_host_bytes, options.reserved_host_what),
          scene_taken ? 1 : 2);
      adaptive = true;
      pilot = m;
      for (int hi = 0; hi < 2; ++hi) {
        Half& h = halves[hi];
        h.sum.assign(npix * 3, 0.0);
        h.sumsq.assign(npix * 3, 0.0);
        h.count.assign(npix, 0u);
        h.launched.assign(npix, 0u);
        h.plan.assign(npix, m);
        h.pilot = render_detail::Pilot{};
        h.piloted = false;
        const bool caustics = packed.params.flags & LC_FLAG_CAUSTICS;
        h.light_sum.assign(caustics ? npix * 3 : 0, 0.0);
        h.light_sumsq.assign(caustics ? npix * 3 : 0, 0.0);
        h.light_paths = 0;
        h.light_totals = {};
      }
      const int width = scene->film.width, height = scene->film.height;
      const int stride = render_detail::calibration_stride(width, height);
      for (int y = stride / 2; y < height; y += stride)
        for (int x = stride / 2; x < width; x += stride)
          calib_pixels.push_back(static_cast<std::size_t>(y) * width + x);
    }
    if (packed.params.flags & LC_FLAG_CAUSTICS) {
      try {
        for (auto& w : workers) w->ensure_light(2 * npix);  // halves A and B
      } catch (const cl::Error& e) {
        throw Error(render_detail::resource_error(e, render_detail::ClStage::Upload, scene->path,
                                                  workers.front()->ctx.device.info.name));
      }
    }
    if (adaptive && pilot != m) {
      throw Error("render_adaptive: min_spp " + std::to_string(o.min_spp) +
                  " differs from the adaptive render in progress (call reset() first)");
    }
    auto planned = [&] {
      std::uint64_t t = 0;
      for (const Half& h : halves)
        for (std::uint32_t n : h.plan) t += n;
      return t;
    };
    begin_call();
    CallState cs;
    std::uint64_t launched_total = 0;
    for (const Half& h : halves)
      for (std::uint32_t n : h.launched) launched_total += n;
    const std::uint64_t call_start = launched_total;
    auto progress = [&] {
      return make_progress(cs, (launched_total - call_start) / npix,
                           (planned() - call_start) / npix, o.max_seconds);
    };
    const double time_limit = o.max_seconds;
    // this call's target, also when a time limit or a cancel stops it in the pilot (it was set
    // after the pilot only: a render stopped there did not look adaptive at all, and `lucent
    // render --target-error E --time T` said nothing of the target it had not reached)
    adaptive_target = o.target_error;
    pilot_done = false;
    Half& calib_half = halves[2];
    if (o.target_error > 0 && calib_half.plan.empty()) {
      // the calibration's pilot: `pilot` samples of stream C in each calibration pixel
      calib_half.sum.assign(npix * 3, 0.0);
      calib_half.sumsq.assign(npix * 3, 0.0);
      calib_half.count.assign(npix, 0u);
      calib_half.launched.assign(npix, 0u);
      calib_half.plan.assign(npix, 0u);
      for (std::size_t i : calib_pixels) calib_half.plan[i] = m;
    }
    // the pilot: `pilot` samples in every pixel of both halves (and C's, above); with a target,
    // without glass splitting: its variances then bound those of the split samples that follow,
    // which keeps room for the tails that no pilot sees where the glass is (a budget's plan wants
    // the split samples' shape instead; docs/rendering-model.md)
    bool piloted = false;
    {
      // the pilot's samples only: what an earlier call's plan left unrendered (a time limit, a
      // cancel) comes after the plans below, with the scene's splits. Restored even when a pass
      // throws, so that later renders split again.
      struct PilotPhase {
        Impl& s;
        std::vector<std::uint32_t> plans[3];
        ~PilotPhase() {
          s.unsplit_passes = false;
          for (int hi = 0; hi < 3; ++hi) s.halves[hi].plan.swap(plans[hi]);
        }
      } phase{*this, {}};
      for (int hi = 0; hi < 3; ++hi) {
        phase.plans[hi] = halves[hi].plan;
        for (std::uint32_t& n : halves[hi].plan) n = std::min(n, m);
      }
      unsplit_passes = o.target_error > 0;
      piloted = render_plans(cs, time_limit, launched_total, call_start, planned(), on_progress);
    }
    if (!piloted) return progress();
    pilot_done = true;
    for (int hi = 0; hi < 2; ++hi) {
      Half& h = halves[hi];
      if (h.piloted) continue;  // its samples are no longer only the pilot's
      // errors weighed by the pixel's value from its neighbours (neighbour_values), and with
      // caustics by the whole pixel, camera and light means
      const int width = scene->film.width, height = scene->film.height;
      const std::vector<double> means = render_detail::sample_means(h.sum, h.count);
      const bool light = !h.light_sum.empty();
      const std::vector<double> lm =
          light ? render_detail::light_means(h.light_sum, h.light_paths, width, height)
                : std::vector<double>();
      const std::vector<double> value =
          render_detail::neighbour_values(means, h.count, width, height, light ? &lm : nullptr);
      h.pilot.v = render_detail::relative_variance(h.sum, h.sumsq, h.count, &value);
      if (light)
        h.pilot.light_w = render_detail::light_relative_variance(h.light_sum, h.light_sumsq,
                                                                 h.light_paths, value);
      calibration_sums(h, h.pilot, &value);
      h.piloted = true;
    }
    render_detail::Pilot c;
    if (o.target_error > 0) calibration_sums(calib_half, c);  // C holds its pilot only
    // each half planned (and, with a target, calibrated) from the other's pilot and C alone: its
    // mean stays unbiased (adaptive.hpp)
    const std::uint32_t max_half = std::max(m, o.max_spp / 2);
    const render_detail::HalfPlans plans =
        render_detail::plan_halves(halves[0].pilot, halves[1].pilot, c, scene->film.width,
                                   scene->film.height, o.target_error, o.budget_spp, m, max_half);
    for (int hi = 0; hi < 2; ++hi) {
      // what an earlier call planned and did not render (a time limit, a cancel) stays planned,
      // but within this call's cap: a call with max_spp 64 after one with 100000 rendered the
      // earlier plan to 100000 samples in a pixel. (Unbiased still: the cap is no sample's.)
      Half& h = halves[hi];
      for (size_t i = 0; i < npix; ++i)
        h.plan[i] = std::max(std::min(h.plan[i], std::max(h.launched[i], max_half)),
                             plans.plan[hi].counts[i]);
      if (o.target_error > 0) {
        calib[hi] = plans.calib[hi];
        planned_relmse[hi] = plans.plan[hi].predicted;
      }
    }
    calibrated = calibrated || o.target_error > 0;
    render_plans(cs, time_limit, launched_total, call_start, planned(), on_progress);
    return progress();
  }

  RenderResult result() const {
    if (!scene) throw Error("result: the session has no scene (call set_scene first)");
    const int width = scene->film.width, height = scene->film.height;
    RenderResult r;
    r.mean = Image{width, height, std::vector<float>(npix * 3)};
    r.variance = Image{width, height, std::vector<float>(npix * 3)};
    r.samples = count;
    if (adaptive) {
      // the average of the halves (render/adaptive.hpp), the relMSE its variances predict with
      // each half's model scaled by its calibration's gain (1 without one), and the halves'
      // a-posteriori estimate
      const Half &a = halves[0], &b = halves[1];
      const double ga = calibrated ? calib[0].gain : 1, gb = calibrated ? calib[1].gain : 1;
      const bool caustics = !a.light_sum.empty();
      std::vector<double> mean_var(npix * 3, 0.0);  // the variance of each pixel's mean
      LightMeanVariance lmv;                        // caustics: the image mean's light part
      for (size_t i = 0; i < npix; ++i) {
        double half_var[2][3];  // each half's variance of its camera mean, from its own samples
        render_detail::combine_halves(&a.sum[i * 3], &a.sumsq[i * 3], a.count[i], &b.sum[i * 3],
                                      &b.sumsq[i * 3], b.count[i], &r.mean.rgb[i * 3],
                                      &r.variance.rgb[i * 3], &r.samples[i], half_var);
        double light_var[3] = {0, 0, 0};  // of the light part (caustics), not scaled by gains
        if (caustics)
          render_detail::add_light_halves(&a.light_sum[i * 3], &a.light_sumsq[i * 3], a.light_paths,
                                          &b.light_sum[i * 3], &b.light_sumsq[i * 3], b.light_paths,
                                          r.samples[i], &r.mean.rgb[i * 3], &r.variance.rgb[i * 3],
                                          light_var);
        if (r.samples[i] == 0) continue;
        // compare reads a pixel of n < 2 as variance 0, its light part too: Q leaves it out
        if (r.samples[i] >= 2)
          for (int c = 0; c < 3; ++c) lmv.pixels[c] += light_var[c];
        // the camera part's var / n is (V_A + V_B) / 4 (V_h = s_h^2 / n_h, combine_halves); the
        // calibrated model's is (g_A V_A + g_B V_B) / 4, one half's g_h V_h alone
        const bool both = a.count[i] > 0 && b.count[i] > 0;
        for (int c = 0; c < 3; ++c)
          mean_var[i * 3 + c] =
              (ga * half_var[0][c] + gb * half_var[1][c]) / (both ? 4 : 1) + light_var[c];
      }
      // errors weighed by each pixel's value from its neighbours (render/adaptive.hpp)
      const std::vector<double> value = render_detail::neighbour_values(
          std::vector<double>(r.mean.rgb.begin(), r.mean.rgb.end()), r.samples, width, height);
      double predicted = 0;
      for (size_t k = 0; k < npix * 3; ++k) predicted += mean_var[k] / (value[k] * value[k] + 0.01);
      r.estimated_relmse = npix ? predicted / (3.0 * double(npix)) : 0;
      if (caustics) {  // each half's whole estimate: its camera mean plus its light part
        std::vector<double> sa = a.sum, sb = b.sum;
        for (size_t k = 0; k < sa.size(); ++k) {
          if (a.light_paths) sa[k] += a.count[k / 3] * a.light_sum[k] / double(a.light_paths);
          if (b.light_paths) sb[k] += b.count[k / 3] * b.light_sum[k] / double(b.light_paths);
        }
        r.halves_relmse = render_detail::halves_relmse(sa, a.count, sb, b.count, &value);
        // the light part is the halves' average (add_light_halves), as their variances combine
        double va[3], vb[3];
        render_detail::light_paths_variance(a.light_totals, a.light_paths, double(npix), va);
        render_detail::light_paths_variance(b.light_totals, b.light_paths, double(npix), vb);
        const bool both = a.light_paths > 0 && b.light_paths > 0;
        for (int c = 0; c < 3; ++c) {
          lmv.paths[c] = both ? (va[c] + vb[c]) / 4 : va[c] + vb[c];
          lmv.pixels[c] /= double(npix) * double(npix);
        }
        // (a half of one path has no variance: then none is known)
        if (a.light_paths != 1 && b.light_paths != 1 && (a.light_paths || b.light_paths))
          r.light_mean_variance = render_detail::finite_or_none(lmv);
      } else {
        r.halves_relmse = render_detail::halves_relmse(a.sum, a.count, b.sum, b.count, &value);
      }
      r.target_error = adaptive_target;
      // how far the plans got: a time limit or a cancel stops a render short of them
      std::uint64_t planned_total = 0;
      for (const Half& h : halves)
        for (size_t i = 0; i < h.plan.size(); ++i) {
          planned_total += h.plan[i];
          if (h.launched[i] < h.plan[i]) r.plan_incomplete = true;
        }
      r.planned_spp = npix ? (planned_total + npix / 2) / npix : 0;  // rounded as spp is
      r.pilot_incomplete = !pilot_done;
      if (calibrated) {
        r.model_gain_a = calib[0].gain;
        r.model_gain_b = calib[1].gain;
        // the last call's plan only: after a budget call the target call's prediction is stale
        // (the gains stay: they still scale estimated_relmse)
        if (adaptive_target > 0) r.planned_relmse = (planned_relmse[0] + planned_relmse[1]) / 4;
      }
    } else {
      LightMeanVariance lmv;  // caustics: the image mean's light part
      for (size_t i = 0; i < npix; ++i) {
        double n = count[i];
        for (int c = 0; c < 3; ++c) {
          double s = sum[i * 3 + c], s2 = sumsq[i * 3 + c];
          double mean = n > 0 ? s / n : 0;
          double var = render_detail::sample_variance(s, s2, n);
          if (light_paths > 1) {
            // the light paths' mean, and its variance in units of one camera sample
            const double N = double(light_paths), lm = light_sum[i * 3 + c] / N;
            const double lvar =
                render_detail::sample_variance(light_sum[i * 3 + c], light_sumsq[i * 3 + c], N) / N;
            mean += lm;
            var += n * lvar;
            // var / n holds it, where compare reads var (a pixel of n < 2 counts 0 there)
            if (n >= 2) lmv.pixels[c] += lvar;
          }
          r.mean.rgb[i * 3 + c] = static_cast<float>(mean);
          r.variance.rgb[i * 3 + c] = static_cast<float>(var);
        }
      }
      if (light_paths > 1) {
        render_detail::light_paths_variance(light_totals, light_paths, double(npix), lmv.paths);
        for (double& p : lmv.pixels) p /= double(npix) * double(npix);
        r.light_mean_variance = render_detail::finite_or_none(lmv);
      }
    }
    r.spp = done;
    r.nonfinite = nonfinite;
    r.rays = rays;
    r.seconds = render_seconds;
    r.build_options = build_options;
    r.cancelled = last_cancelled;
    r.seed = scene->integrator.seed;
    r.sampler = lucent::type_name(scene->integrator.sampler);
    for (const auto& w : workers) {
      if (w->program) {
        r.build_seconds = std::max(r.build_seconds, w->program->build_seconds);
        r.program_cache_hit = w->program->cache_hit;
      }
      r.device += (r.device.empty() ? "" : " + ") + w->share.device;
      r.devices.push_back(w->share);
    }
    return r;
  }
};

Renderer::Renderer(SessionOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {}

Renderer::Impl& Renderer::impl() const {
  // (a moved-from Renderer: its methods dereferenced a null pointer)
  if (!impl_) throw Error("this lucent::Renderer was moved from: it holds no session");
  return *impl_;
}
Renderer::~Renderer() {
  // in a process forked from the one that made the session: releasing its OpenCL objects hangs
  // (the driver's threads stayed in the parent), as every other call would (check_not_forked)
  if (impl_ && cl_util::forked_after_opencl()) {
    (void)impl_.release();  // left to the process's end
    return;
  }
  // destroyed during its own call (from a render's on_progress, set_scene's warning sink, or
  // another thread): the call would go on in freed memory (SIGSEGV, or PoCL's abort on a
  // destroyed mutex). A destructor cannot refuse: end the process with a line saying why.
  if (impl_ && impl_->rendering.load()) {
    std::fputs(
        "lucent: a lucent::Renderer was destroyed during one of its own calls (from its "
        "on_progress or warning sink, run_convergence's on_point, or another thread): "
        "aborting\n",
        stderr);
    std::abort();
  }
}
// (moving a session from its own on_progress: the render went on in an Impl moved away, or
// destroyed by the assignment: SIGSEGV)
Renderer::Renderer(Renderer&& other) {
  if (other.impl_) other.impl_->check_not_rendering("moving a Renderer");
  impl_ = std::move(other.impl_);
}
Renderer& Renderer::operator=(Renderer&& other) {
  if (this == &other) return *this;
  if (impl_) impl_->check_not_rendering("assigning to a Renderer");
  if (other.impl_) other.impl_->check_not_rendering("moving a Renderer");
  impl_ = std::move(other.impl_);
  return *this;
}

const DeviceInfo& Renderer::device() const { return impl().device_infos.front(); }
std::vector<DeviceInfo> Renderer::devices() const { return impl().device_infos; }
const SessionOptions& Renderer::options() const { return impl().options; }

void Renderer::set_build_options(Precision precision, bool fast_math, bool specialize) {
  Impl::RenderCall busy(impl(), "set_build_options");
  if (precision != Precision::Float && precision != Precision::Double)  // (7 was taken as float)
    throw Error("set_build_options: unknown precision " +
                std::to_string(static_cast<int>(precision)));
  // (without a scene too: it was accepted, and refused at the next set_scene)
  for (const DeviceInfo& d : impl().device_infos)
    render_detail::check_precision_support(d, precision);
  const SessionOptions before = impl().options;
  impl().options.precision = precision;
  impl().options.fast_math = fast_math;
  impl().options.specialize = specialize;
  try {
    if (impl().scene) {
      // a copy (two descriptions while it packs, as the estimate counts a copied scene); the
      // application still holds its own or not, as before
      const bool taken = impl().scene_taken;
      impl().set_scene(Scene(*impl().scene));
      impl().scene_taken = taken;
    }
  } catch (...) {
    // refused (a device without fp64, a kernel that does not build): the options stay those
    // the session's programs were built with
    impl().options.precision = before.precision;
    impl().options.fast_math = before.fast_math;
    impl().options.specialize = before.specialize;
    throw;
  }
}

void Renderer::set_scene(const Scene& scene) {
  Impl::RenderCall busy(impl(), "set_scene");
  impl().set_scene(scene);
}

void Renderer::set_scene(Scene&& scene) {
  Impl::RenderCall busy(impl(), "set_scene");
  impl().set_scene(scene, &scene);
}

void Renderer::set_camera(const Camera& camera) {
  Impl::RenderCall busy(impl(), "set_camera");
  impl().set_camera(camera);
}

const Scene& Renderer::scene() const {
  if (!impl().scene) throw Error("the session has no scene (call set_scene first)");
  return *impl().scene;
}

RenderProgress Renderer::render(std::uint64_t spp,
                                const std::function<void(const RenderProgress&)>& on_progress) {
  if (spp == 0) throw Error("render: the number of samples per pixel must be positive");
  return impl().run(spp, 0, on_progress);
}

RenderProgress Renderer::render_for(double seconds,
                                    const std::function<void(const RenderProgress&)>& on_progress) {
  if (!(seconds > 0) || !std::isfinite(seconds))
    throw Error("render_for: the time must be a positive number of seconds");
  return impl().run(0, seconds, on_progress);
}

RenderProgress Renderer::render_adaptive(
    const AdaptiveOptions& options, const std::function<void(const RenderProgress&)>& on_progress) {
  return impl().run_adaptive(options, on_progress);
}

RenderProgress Renderer::render(std::uint64_t spp, double max_seconds,
                                const std::function<void(const RenderProgress&)>& on_progress) {
  if (spp == 0 && !(max_seconds > 0))
    throw Error("render: give a number of samples per pixel, a time limit or both");
  if (!(max_seconds >= 0) || !std::isfinite(max_seconds))
    throw Error("render: the time limit must be a non-negative number of seconds");
  return impl().run(spp, max_seconds, on_progress);
}

void Renderer::reset(std::uint64_t first_sample) {
  Impl::RenderCall busy(impl(), "reset");
  if (first_sample > 0xffffffffull) throw Error("reset: the first sample index must be below 2^32");
  impl().clear_accumulation(first_sample);
}

RenderResult Renderer::result() const { return impl().result(); }

Accumulation Renderer::accumulation() const {
  const Impl& m = impl();
  if (!m.scene) throw Error("accumulation: the session has no scene (call set_scene first)");
  // an adaptive render's samples are in its halves, per-pixel counts of two streams, which a
  // contiguous range of sample indices cannot describe (this returned zero sums claiming them)
  if (m.adaptive)
    throw Error(
        "accumulation: the session holds an adaptive render, which is not a range of sample "
        "indices (part files and MPI ranks take renders of a fixed number of samples)");
  Accumulation a;
  a.width = m.scene->film.width;
  a.height = m.scene->film.height;
  a.sum = m.sum;
  a.sumsq = m.sumsq;
  a.count = m.count;
  a.light_sum = m.light_sum;
  a.light_sumsq = m.light_sumsq;
  a.light_paths = m.light_paths;
  // with a gap (a device's pass failed, later passes of others were kept) the samples are not one
  // range from first_sample: a part claiming [first, first + spp) would be wrong
  if (m.end_index != m.first + m.done) {
    const std::string held = "accumulation: the session holds " + std::to_string(m.done) +
                             " samples per pixel of [" + std::to_string(m.first) + ", " +
                             std::to_string(m.end_index) + "), not one range from " +
                             std::to_string(m.first);
    // (from a render's on_progress with several devices: another device's pass is not done
    // yet; this blamed a failed pass)
    if (m.in_render.load())
      throw Error(held +
                  " (another device's pass is still under way): read it once the render has "
                  "returned");
    throw Error(held +
                " (a device's pass failed while others' later passes were kept); call reset() to "
                "render a part again");
  }
  a.first_sample = m.first;
  a.spp = m.done;
  a.nonfinite = m.nonfinite;
  a.rays = m.rays;
  a.seconds = m.render_seconds;
  return a;
}

std::uint64_t Renderer::image_hash() const {
  const Impl& m = impl();
  if (!m.scene) throw Error("image_hash: the session has no scene (call set_scene first)");
  std::uint64_t h = 14695981039346656037ull;  // FNV-1a, 64 bits
  auto add = [&h](const void* data, size_t size) {
    const unsigned char* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < size; ++i) h = (h ^ p[i]) * 1099511628211ull;
  };
  lc_params P = m.packed.params;  // the per-pass fields are not part of the image
  P.sample_offset = P.samples_per_pass = 0;
  add(&P, sizeof P);
#define LUCENT_HASH(name, type, ...)                    \
  {                                                     \
    const std::uint64_t n = m.packed.name.size();       \
    add(&n, sizeof n);                                  \
    if (n) add(m.packed.name.data(), n * sizeof(type)); \
  }
  LC_SCENE_BUFFERS(LUCENT_HASH)
#undef LUCENT_HASH
  add(m.build_options.data(), m.build_options.size());
  // the kernel of the session's build options (after a failed set_scene a worker's program may be
  // another's)
  const std::uint64_t source_hash = m.workers.front()->programs.at(m.build_options).source_hash;
  add(&source_hash, sizeof source_hash);
  return h;
}
std::uint64_t Renderer::spp() const { return impl().done; }
std::uint64_t Renderer::first_sample() const { return impl().first; }
void Renderer::cancel() { impl().cancel_requested = true; }
void Renderer::set_cancel_flag(const std::atomic<bool>* flag) { impl().cancel_flag = flag; }
const std::atomic<bool>* Renderer::cancel_flag() const { return impl().cancel_flag; }
SessionStats Renderer::stats() const { return impl().stats; }

namespace render_detail {

CancelScope::CancelScope(Renderer& renderer, const char* call, const std::atomic<bool>* flag)
    : renderer_(renderer) {
  Renderer::Impl& s = renderer_.impl();
  // the session held while the scope begins, as a call holds it: refused (nothing changed) during
  // another call, and no render starts between the check and the changes
  cl_util::check_not_forked();
  if (s.rendering.exchange(true)) throw s.rendering_error(call);
  if (s.cancel_scopes++ == 0) s.cancel_requested = false;
  if (flag) {
    flag_before_ = s.cancel_flag.exchange(flag);
    flag_replaced_ = true;
  }
  s.rendering = false;
}
CancelScope::~CancelScope() {
  Renderer::Impl& s = *renderer_.impl_;
  if (flag_replaced_) s.cancel_flag = flag_before_;
  --s.cancel_scopes;
}
bool CancelScope::cancelled() const { return renderer_.impl_->cancelled(); }
void CancelScope::hold(const char* what, const std::function<void()>& f) {
  Renderer::Impl& s = *renderer_.impl_;
  if (s.rendering.exchange(true)) throw s.rendering_error(what);
  s.held_by = what;
  struct Release {
    Renderer::Impl& s;
    ~Release() {
      s.held_by = nullptr;
      s.rendering = false;
    }
  } release{s};
  f();
}

}  // namespace render_detail

}  // namespace lucent
