#include "render/resources.hpp"

#include <algorithm>
#include <atomic>
#include <initializer_list>
#include <type_traits>

#include "bvh/bvh.hpp"
#include "core/host_memory.hpp"
#include "lucent/error.hpp"
#include "render/device_scene.hpp"
#include "render/features.hpp"
#include "render/pack.hpp"

namespace lucent::render_detail {

using sys::bytes_add;
using sys::bytes_mul;
using sys::host_memory;
using sys::HostMemory;

namespace {

const DeviceLimits* g_override = nullptr;

std::uint64_t lowered(std::uint64_t real, std::uint64_t override) {
  if (override == 0) return real;
  return real == 0 ? override : std::min(real, override);
}

std::string scene_name(const Scene& scene) { return scene.path.empty() ? "scene" : scene.path; }

std::string film_size(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

/// What to reduce when a scene buffer is too large, by its LC_SCENE_BUFFERS name.
std::string reduce_buffer(const std::string& name) {
  if (name == "nodes" || name == "leaves") return "the number of triangles and spheres";
  if (name == "triangles" || name == "tri_attrs") return "the number of triangles";
  if (name == "spheres") return "the number of spheres";
  if (name == "materials") return "the number of materials";
  if (name == "lights") return "the number of lights (every emissive triangle is one)";
  if (name == "light_cdf") return "the environment map's resolution";
  return "the textures' resolution";  // textures, texels
}

const MemoryPart& largest(const std::vector<MemoryPart>& parts) {
  return *std::max_element(
      parts.begin(), parts.end(),
      [](const MemoryPart& a, const MemoryPart& b) { return a.bytes < b.bytes; });
}

}  // namespace

std::uint64_t total_bytes(const std::vector<MemoryPart>& parts) {
  std::uint64_t t = 0;
  for (const MemoryPart& p : parts) t = bytes_add(t, p.bytes);
  return t;
}

bool buffers_in_host_memory(const cl::Device& device) {
  return (device.getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_CPU) != 0;
}

DeviceLimits DeviceLimits::of(const cl_util::Device& device) {
  DeviceLimits d;
  d.max_alloc = device.device.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>();
  d.global_mem = device.device.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
  d.host_mem = host_memory_allowed(&d.host_what);
  d.host_unified = buffers_in_host_memory(device.device);
  d.fp64 = device.info.fp64;
  d.light_double = light_sums_double(device.info);
  d.device = device.info.name;
  if (g_override) {
    d.max_alloc = lowered(d.max_alloc, g_override->max_alloc);
    d.global_mem = lowered(d.global_mem, g_override->global_mem);
  }
  return d;
}

DeviceLimits DeviceLimits::cpu() {
  DeviceLimits d;
  d.device = "CPU";
  d.host_unified = d.fp64 = d.light_double = true;
  return d;
}

ScopedLimitOverride::ScopedLimitOverride(const DeviceLimits& limits) {
  delete g_override;
  g_override = new DeviceLimits(limits);
  sys::set_host_limit_override(limits.host_mem);
}

ScopedLimitOverride::~ScopedLimitOverride() {
  delete g_override;
  g_override = nullptr;
  sys::set_host_limit_override(0);
}

namespace {
bool g_upload_fault = false;
}  // namespace

ScopedUploadFault::ScopedUploadFault() { g_upload_fault = true; }
ScopedUploadFault::~ScopedUploadFault() { g_upload_fault = false; }
bool upload_fault() { return g_upload_fault; }

namespace {
std::atomic<std::uint64_t> g_pass_fault{~std::uint64_t(0)};
}  // namespace

ScopedPassFault::ScopedPassFault(std::uint64_t begin) { g_pass_fault = begin; }
ScopedPassFault::~ScopedPassFault() { g_pass_fault = ~std::uint64_t(0); }
bool pass_fault(std::uint64_t begin) { return g_pass_fault.load() == begin; }

namespace {
std::atomic<std::uint32_t> g_counter_start{0};
}  // namespace

ScopedCounterStart::ScopedCounterStart(std::uint32_t start) { g_counter_start = start; }
ScopedCounterStart::~ScopedCounterStart() { g_counter_start = 0; }
std::uint32_t counter_start() { return g_counter_start.load(); }

namespace {

struct PackedSizes {
  std::uint64_t ntri = 0, nsph = 0, sph_bytes = 0, tex_bytes = 0;
};

// the packed scene (pack.cpp): a triangle and its attributes, a sphere, a texel as float4, and
// an environment map's sampling table (a float per texel)
PackedSizes packed_sizes(const Scene& scene) {
  PackedSizes z;
  z.ntri = scene.triangles.size();
  z.nsph = scene.spheres.size();
  z.sph_bytes = z.nsph * sizeof(lc_sphere);
  for (const Texture& t : scene.textures)
    z.tex_bytes += std::uint64_t(t.width) * std::uint64_t(t.height) * sizeof(lc_float4);
  for (const Light& l : scene.lights)
    if (l.type == LightType::EnvironmentMap && l.texture >= 0 &&
        size_t(l.texture) < scene.textures.size()) {
      const Texture& t = scene.textures[size_t(l.texture)];
      z.tex_bytes += (std::uint64_t(t.width) * std::uint64_t(t.height) + 1) * sizeof(float);
    }
  return z;
}

}  // namespace

std::uint64_t description_bytes(const Scene& scene) {
  // what the vectors hold (their capacities: a loader's growth leaves up to twice the size)
  auto held = [](const auto& v) {
    return std::uint64_t(v.capacity()) * sizeof(typename std::decay_t<decltype(v)>::value_type);
  };
  std::uint64_t b = held(scene.materials) + held(scene.spheres) + held(scene.positions) +
                    held(scene.normals) + held(scene.uvs) + held(scene.triangles) +
                    held(scene.lights) + held(scene.textures) + held(scene.shapes);
  for (const Texture& t : scene.textures) b += held(t.rgba);
  return b;
}

std::vector<MemoryPart> reserved_part(std::uint64_t reserved, const std::string& what) {
  if (reserved == 0) return {};
  if (!what.empty()) return {{what, reserved, "the film size"}};
  // (lucent render declares its outputs, which the film size sets; a library caller's bytes may
  // be anything: "reduce the film size" blamed the film for them)
  return {{"what the application keeps beside the session (its outputs, as it declared them)",
           reserved, "the film size, or what the application declares it keeps"}};
}

std::vector<MemoryPart> estimate_host_memory(const Scene& scene,
                                             const std::vector<DeviceLimits>& devices,
                                             int description_copies) {
  const std::uint64_t npix = std::uint64_t(scene.film.width) * std::uint64_t(scene.film.height);
  const std::string film = film_size(scene.film.width, scene.film.height);
  std::vector<MemoryPart> parts;
  // session.cpp: double sums and sums of squares (3 + 3) and a sample count per pixel; the
  // result's mean and variance (3 + 3 floats) and sample counts
  parts.push_back({"the accumulation and result images of the " + film + " film",
                   bytes_mul(npix, kAccumulationPixelBytes + kResultPixelBytes), "the film size"});
  // caustics: the light paths' sums and sums of squares (3 + 3 doubles per pixel), when the
  // scene has a delta surface (pack_scene drops caustics from one without: `lucent info` counted
  // 7 MiB of them for a scene whose caustics it said were off)
  const bool caustics = light_traced_caustics(scene);
  if (caustics)
    parts.push_back({"the caustics light sums of the " + film + " film",
                     bytes_mul(npix, 6 * sizeof(double)),
                     "the film size, or render without caustics"});
  // the scene description: the application's, and the session's copy of it (Renderer::scene),
  // or only the session's where it took the application's
  parts.push_back({"the scene description (" + std::to_string(scene.triangles.size()) +
                       " triangles, " + std::to_string(scene.positions.size()) + " vertices, " +
                       std::to_string(scene.textures.size()) + " textures)" +
                       (description_copies > 1 ? ", the application's and the session's copy" : ""),
                   description_bytes(scene) * std::uint64_t(std::max(description_copies, 0)),
                   "the number of triangles or the textures' resolution"});
  const PackedSizes z = packed_sizes(scene);
  const std::uint64_t ntri = z.ntri, nsph = z.nsph, sph_bytes = z.sph_bytes,
                      tex_bytes = z.tex_bytes;
  // the BVH (bvh_build.cpp, bvh_wide.cpp): the build's primitive references (32 bytes) and scratch
  // binary tree (at most 2 nodes per primitive), then the tree collapsed directly while its pages
  // go back, beside the primitive indices and the collapse's choices (9 bytes per interior node)
  // and the growing wide tree: its leaf blocks (at most one per primitive: a soup of separate
  // triangles has leaves of one, a mesh about one block per 2 or 3 primitives) and nodes (a soup
  // 0.29 per primitive, the dragon 0.06: counted as one per 3). The second phase is the larger:
  // the scratch tree, indices and choices are counted beside the whole wide tree (a 10^6-triangle
  // soup peaked at 251 bytes a primitive, counted 322; the scratch tree's depth-first copy, no
  // longer made, took 323)
  const std::uint64_t nprim = ntri + nsph;
  const std::uint64_t leaf_bytes = (nprim + 1) * sizeof(lc_bvh_leaf);
  const std::uint64_t node_bytes = (nprim / 3 + 1) * sizeof(lc_bvh_node);
  const std::uint64_t bvh_tree = leaf_bytes + node_bytes;
  const std::uint64_t bvh_bytes = nprim * (2 * sizeof(bvh::Node2) + sizeof(lc_uint) + 9) + bvh_tree;
  // the packed arrays: each of 1 MiB or more takes whole huge pages (core/host_blocks.hpp). A CPU
  // device's scene buffers are those arrays themselves (device_scene.hpp's read_only_buffer), so
  // they are counted once whatever the devices; another device's are in its own memory.
  parts.push_back({"the " + std::to_string(ntri) + " triangles",
                   host_block_bytes(ntri * sizeof(lc_triangle)) +
                       host_block_bytes(ntri * sizeof(lc_triangle_attr)),
                   "the number of triangles"});
  parts.push_back({"the " + std::to_string(nsph) + " spheres", host_block_bytes(sph_bytes),
                   "the number of spheres"});
  parts.push_back({"the texels of the " + std::to_string(scene.textures.size()) + " textures",
                   host_block_bytes(tex_bytes), "the textures' resolution"});
  // the light table (lights.cpp): a packed light and its selection CDF entry each, and
  // pack_lights' powers and probabilities (two doubles) beside them; every emissive shape is a
  // light (2e6 point lights took 2.7 times what was counted without it)
  std::uint64_t nlight = scene.lights.size();
  auto emissive = [&scene](int material) {
    return material >= 0 && size_t(material) < scene.materials.size() &&
           scene.materials[size_t(material)].emissive();
  };
  for (const Triangle& t : scene.triangles) nlight += emissive(t.material);
  for (const Sphere& sp : scene.spheres) nlight += emissive(sp.material);
  parts.push_back({"the table of " + std::to_string(nlight) + " lights",
                   host_block_bytes(nlight * sizeof(lc_light)) +
                       host_block_bytes(nlight * sizeof(float)) + nlight * 2 * sizeof(double),
                   "the number of lights (every emissive triangle is one)"});
  parts.push_back(
      {"the BVH of " + std::to_string(nprim) + " primitives",
       bvh_bytes - bvh_tree + host_block_bytes(leaf_bytes) + host_block_bytes(node_bytes),
       "the number of triangles and spheres"});
  for (const DeviceLimits& d : devices) {
    // the device's pass sums (double4 with fp64, else float4; with caustics twice as many, the
    // light paths' totals after them) and with caustics its light sums (double4 with fp64 and
    // 64-bit atomics, else float4: two films each, an adaptive work list's halves A and B)
    const std::uint64_t sum_elem = d.fp64 ? sizeof(cl_double4) : sizeof(cl_float4);
    const std::uint64_t light_elem = d.light_double ? sizeof(cl_double4) : sizeof(cl_float4);
    const std::uint64_t light_bufs = bytes_mul(npix, (caustics ? 4 : 0) * light_elem);
    const std::uint64_t film_bufs =
        bytes_add(bytes_mul(npix, (caustics ? 4 : 2) * sum_elem), light_bufs);
    // a CPU device's buffers are host memory: the film's (and the work list), and the scene's
    // (the packed arrays, counted above); its pass results are mapped there (session.cpp).
    // Another device's results are read back into host copies as large as its buffers (h_sum,
    // h_sumsq, and with caustics h_light, h_lightsq).
    std::uint64_t bytes = film_bufs;
    if (d.host_unified) bytes = bytes_add(bytes, bytes_mul(npix, sizeof(cl_uint4)));
    parts.push_back({"the buffers of device '" + d.device + "' for the " + film + " film" +
                         (d.host_unified ? " (host memory)" : ""),
                     bytes, "the film size"});
  }
  return parts;
}

namespace {

// `before_devices`: the devices are not chosen yet (lucent render's first check), so their
// buffers, host memory on a CPU device, are not in `parts`: the need is a lower bound (it said
// 20 GiB for a 16384x16384 film where lucent info said 40 on the CPU device).
void check_host_parts(const Scene& scene, const std::vector<MemoryPart>& parts,
                      std::uint64_t host_limit, const std::string& limit_what,
                      bool before_devices = false, const char* doing = "rendering") {
  const std::uint64_t need = total_bytes(parts);
  if (need <= host_limit) return;
  const MemoryPart& big = largest(parts);
  throw Error(scene_name(scene) + ": " + doing + " needs " +
              (before_devices ? "at least about " : "about ") + format_bytes(need) +
              " of host memory" + (before_devices ? " before its devices' buffers" : "") +
              ", more than the limit of " + format_bytes(host_limit) + " (80% of " + limit_what +
              "); the largest part is " + big.what + " (" + format_bytes(big.bytes) + "): reduce " +
              big.reduce);
}

}  // namespace

void check_host_memory(const Scene& scene, const std::vector<DeviceLimits>& devices,
                       std::uint64_t host_limit, const std::string& limit_what,
                       const std::vector<MemoryPart>& extra, int description_copies) {
  if (host_limit == 0) return;
  std::vector<MemoryPart> parts = estimate_host_memory(scene, devices, description_copies);
  parts.insert(parts.end(), extra.begin(), extra.end());
  check_host_parts(scene, parts, host_limit, limit_what, devices.empty());
}

void check_packing_host_memory(const Scene& scene, int description_copies) {
  std::string what;
  const std::uint64_t limit = host_memory_allowed(&what);
  if (limit == 0) return;
  std::vector<MemoryPart> parts;  // the estimate less the film's parts (their reduce names it)
  for (MemoryPart& p : estimate_host_memory(scene, {}, description_copies))
    if (p.reduce.rfind("the film size", 0) != 0) parts.push_back(std::move(p));
  check_host_parts(scene, parts, limit, what, false, "packing it (its BVH and buffers)");
}

void check_output_host_memory(const Scene& scene, const std::vector<MemoryPart>& outputs) {
  std::string what;
  const std::uint64_t limit = host_memory_allowed(&what);
  if (limit == 0) return;
  check_host_parts(scene, outputs, limit, what);
}

std::uint64_t host_memory_allowed(std::string* what) { return sys::host_memory_allowed(what); }

void check_reference_host_memory(const Scene& scene, int threads) {
  std::string what;
  const std::uint64_t limit = host_memory_allowed(&what);
  if (limit == 0) return;
  // the kernel's estimate without devices: the reference's accumulation (mean and M2 in double,
  // a count) and result images take what the session's do; with caustics each thread keeps its
  // own light sums (src/reference/render.cpp)
  // (the reference traces light paths whenever caustics are asked for on the path integrator,
  // a delta surface or not, where the kernel's estimate counts them only with one)
  std::vector<MemoryPart> parts = estimate_host_memory(scene, {});
  parts.erase(std::remove_if(parts.begin(), parts.end(),
                             [](const MemoryPart& p) {
                               return p.what.rfind("the caustics light sums", 0) == 0;
                             }),
              parts.end());
  if (scene.integrator.caustics && scene.integrator.type == IntegratorType::Path) {
    const std::uint64_t npix = std::uint64_t(scene.film.width) * std::uint64_t(scene.film.height);
    parts.push_back(
        {"the caustics light sums of the " + film_size(scene.film.width, scene.film.height) +
             " film, one per thread (" + std::to_string(threads) + ")",
         bytes_mul(bytes_mul(npix, 6 * sizeof(double)), std::uint64_t(std::max(threads, 1))),
         "the film size or the reference's threads, or render without caustics"});
  }
  check_host_parts(scene, parts, limit, what);
}

std::uint64_t adaptive_host_bytes(std::uint64_t npix, bool caustics) {
  // a half: 3 + 3 doubles and 3 uint32; a pilot: 7 doubles and a uint32; the temporaries of
  // the pilots' relative variances (sample means, light means, neighbour values) and of the
  // result (variances of the means, neighbour values, the image's means): about 12 doubles
  const std::uint64_t half = 6 * sizeof(double) + 3 * sizeof(std::uint32_t);
  const std::uint64_t pilot = 7 * sizeof(double) + sizeof(std::uint32_t);
  std::uint64_t per_pixel = 3 * half + 2 * pilot + 12 * sizeof(double);
  if (caustics) per_pixel += 2 * 6 * sizeof(double);
  return bytes_mul(npix, per_pixel);
}

void check_adaptive_host_memory(const Scene& scene, const std::vector<DeviceLimits>& devices,
                                bool caustics, std::uint64_t host_limit,
                                const std::string& limit_what, const std::vector<MemoryPart>& extra,
                                int description_copies) {
  if (host_limit == 0) return;
  std::vector<MemoryPart> parts = estimate_host_memory(scene, devices, description_copies);
  parts.insert(parts.end(), extra.begin(), extra.end());
  const std::uint64_t npix = std::uint64_t(scene.film.width) * std::uint64_t(scene.film.height);
  parts.push_back({"the halves, pilots and plans of adaptive sampling for the " +
                       film_size(scene.film.width, scene.film.height) + " film",
                   adaptive_host_bytes(npix, caustics),
                   "the film size, or render a fixed number of samples (no --target-error)"});
  check_host_parts(scene, parts, host_limit, limit_what);
}

std::vector<MemoryPart> film_device_buffers(int width, int height, bool caustics, bool fp64,
                                            bool light_double) {
  const std::uint64_t npix = std::uint64_t(width) * std::uint64_t(height);
  const std::string film = film_size(width, height);
  // session.cpp's Worker: the work list, the pass sums (double4 with fp64; with caustics the
  // light paths' totals after them, twice the elements), and the light paths' sums (one element
  // each without caustics; double4 with fp64 and 64-bit atomics)
  const std::uint64_t sum = (caustics ? 2 : 1) * (fp64 ? sizeof(cl_double4) : sizeof(cl_float4));
  const std::uint64_t light = light_double ? sizeof(cl_double4) : sizeof(cl_float4);
  std::vector<MemoryPart> parts = {
      {"film sample sums (" + film + ")", bytes_mul(npix, sum), "the film size"},
      {"film sums of squares (" + film + ")", bytes_mul(npix, sum), "the film size"},
      {"film work list (" + film + ")", bytes_mul(npix, sizeof(cl_uint4)), "the film size"}};
  const std::uint64_t nl = caustics ? 2 * npix : 1;  // an adaptive work list's halves A and B
  parts.push_back({"caustics light sums (" + film + ")", bytes_mul(nl, light),
                   caustics ? "the film size, or render without caustics" : "the film size"});
  parts.push_back({"caustics light sums of squares (" + film + ")", bytes_mul(nl, light),
                   caustics ? "the film size, or render without caustics" : "the film size"});
  return parts;
}

void check_device_memory(const Scene& scene, const PackedScene& packed,
                         const DeviceLimits& limits) {
  std::vector<MemoryPart> parts;
  // OpenCL forbids empty buffers: an empty one keeps one element (device_scene.cpp)
#define LUCENT_BUFFER_PART(name, type, what)                                            \
  parts.push_back({what, std::max<std::uint64_t>(packed.name.size(), 1) * sizeof(type), \
                   reduce_buffer(#name)});
  LC_SCENE_BUFFERS(LUCENT_BUFFER_PART)
#undef LUCENT_BUFFER_PART
  for (MemoryPart& p : film_device_buffers(scene.film.width, scene.film.height,
                                           (packed.params.flags & LC_FLAG_CAUSTICS) != 0,
                                           limits.fp64, limits.light_double))
    parts.push_back(std::move(p));
  const std::string device = "device '" + limits.device + "'";
  // the largest buffer is the one to reduce first
  const MemoryPart& big = largest(parts);
  if (limits.max_alloc > 0 && big.bytes > limits.max_alloc)
    throw Error(scene_name(scene) + ": the " + big.what + " need a buffer of " +
                format_bytes(big.bytes) + ", more than the " + format_bytes(limits.max_alloc) +
                " " + device + " allows per buffer (CL_DEVICE_MAX_MEM_ALLOC_SIZE): reduce " +
                big.reduce);
  const std::uint64_t need =
      bytes_add(total_bytes(parts), sizeof(lc_params) + LC_COUNTER_COUNT * sizeof(lc_uint));
  if (limits.global_mem > 0 && need > limits.global_mem)
    throw Error(scene_name(scene) + ": the scene and film buffers need " + format_bytes(need) +
                " on " + device + ", more than its " + format_bytes(limits.global_mem) +
                " of global memory (CL_DEVICE_GLOBAL_MEM_SIZE); the largest is the " + big.what +
                " (" + format_bytes(big.bytes) + "): reduce " + big.reduce);
}

std::string resource_error(const cl::Error& e, ClStage stage, const std::string& scene_path,
                           const std::string& device) {
  const cl_int code = e.err();
  if (code != CL_OUT_OF_RESOURCES && code != CL_MEM_OBJECT_ALLOCATION_FAILURE &&
      code != CL_OUT_OF_HOST_MEMORY)
    return cl_util::describe(e);
  const std::string call = e.what() ? e.what() : "OpenCL";
  std::string doing, reduce;
  if (stage == ClStage::Upload) {
    doing = "creating the scene and film buffers";
    reduce = "the film size, the textures' resolution or the number of triangles";
  } else if (call.find("clEnqueueRead") != std::string::npos) {
    doing = "reading a pass back";
    reduce = "the film size";
  } else {
    doing = "running a pass";
    reduce = "the film size, max_depth or the samples per pass (a shorter pass time)";
  }
  return (scene_path.empty() ? std::string("scene") : scene_path) + ": device '" + device +
         "' ran out of " + (code == CL_OUT_OF_HOST_MEMORY ? "host memory" : "memory or resources") +
         " " + doing + " (" + call + ": " + cl_util::error_name(code) + "): reduce " + reduce;
}

std::size_t work_group_size(std::size_t preferred, std::size_t device_max, std::size_t item_max,
                            std::size_t kernel_max) {
  std::size_t limit = preferred;
  for (std::size_t m : {device_max, item_max, kernel_max})
    if (m > 0) limit = std::min(limit, m);
  std::size_t g = 1;
  while (g * 2 <= limit) g *= 2;
  return g;
}

}  // namespace lucent::render_detail
