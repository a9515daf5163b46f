#pragma once
// Bounded resources: what a scene asks of the host and of each device, checked before anything
// large is allocated, and OpenCL's out-of-resources errors turned into a message saying what to
// reduce. Every refusal is one line naming the scene, the culprit and the limit.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "cl/context.hpp"
#include "core/host_memory.hpp"
#include "lucent/scene.hpp"
#include "render/pack.hpp"

namespace lucent::render_detail {

using sys::format_bytes;
using sys::host_memory_limit;

/// A CPU device: its buffers are host memory. A session maps its pass results there instead of
/// copying them (session.cpp), and the host memory estimate counts its buffers.
bool buffers_in_host_memory(const cl::Device& device);

/// The limits a scene is checked against. Tests shrink them to exercise the checks without
/// allocating; 0 means "no limit known".
struct DeviceLimits {
  std::uint64_t max_alloc = 0;   ///< CL_DEVICE_MAX_MEM_ALLOC_SIZE: the largest buffer
  std::uint64_t global_mem = 0;  ///< CL_DEVICE_GLOBAL_MEM_SIZE: all buffers together
  std::uint64_t host_mem = 0;    ///< what lucent allows itself on the host (sys::host_memory_limit)
  std::string host_what = "physical memory";  ///< what host_mem is 80% of, for messages
  bool host_unified = false;  ///< the device's buffers live in host memory (a CPU device)
  bool fp64 = false;          ///< a pass's sums are double4 (LC_ACCUM_DOUBLE), else float4
  bool light_double = false;  ///< the light sums are double4 (LC_LIGHT_DOUBLE), else float4
  std::string device;         ///< the device's name, for messages

  /// The limits of an OpenCL device, with host_mem = host_memory_limit(), each lowered to the
  /// override's where it sets one (ScopedLimitOverride).
  static DeviceLimits of(const cl_util::Device& device);
  /// A CPU device as PoCL's (buffers in host memory, fp64 and 64-bit atomics), named "CPU", no
  /// memory sizes: what `lucent info` and Python's scene_info estimate for, opening no device.
  static DeviceLimits cpu();
};

/// For tests: while alive, DeviceLimits::of lowers every limit to the override's non-zero ones,
/// so that a session refuses a small scene as it would a huge one, without allocating. Not
/// thread-safe; one at a time.
class ScopedLimitOverride {
 public:
  explicit ScopedLimitOverride(const DeviceLimits& limits);
  ~ScopedLimitOverride();
  ScopedLimitOverride(const ScopedLimitOverride&) = delete;
  ScopedLimitOverride& operator=(const ScopedLimitOverride&) = delete;
};

/// For tests: while alive, a session's set_scene fails with CL_MEM_OBJECT_ALLOCATION_FAILURE
/// right after it has updated a device's scene buffers, as an allocation failing part-way through
/// an upload would (upload_fault()). One at a time.
class ScopedUploadFault {
 public:
  ScopedUploadFault();
  ~ScopedUploadFault();
  ScopedUploadFault(const ScopedUploadFault&) = delete;
  ScopedUploadFault& operator=(const ScopedUploadFault&) = delete;
};
/// Whether a ScopedUploadFault is alive.
bool upload_fault();

/// For tests: while alive, the pass of a uniform render whose first sample index is `begin` fails
/// with CL_OUT_OF_RESOURCES, as a device's failing launch would (pass_fault()). One at a time.
class ScopedPassFault {
 public:
  explicit ScopedPassFault(std::uint64_t begin);
  ~ScopedPassFault();
  ScopedPassFault(const ScopedPassFault&) = delete;
  ScopedPassFault& operator=(const ScopedPassFault&) = delete;
};
/// Whether a ScopedPassFault for `begin` is alive.
bool pass_fault(std::uint64_t begin);

/// For tests: while alive, the low words of a pass's counters (rays, non-finite samples; each a
/// 64-bit count in two 32-bit words, kernels/shared/types.h) start at `start` instead of 0, and
/// the session takes `start` off the count it reads back: a pass of a few rays then carries past
/// 2^32 as one of billions would (counter_start()). One at a time.
class ScopedCounterStart {
 public:
  explicit ScopedCounterStart(std::uint32_t start);
  ~ScopedCounterStart();
  ScopedCounterStart(const ScopedCounterStart&) = delete;
  ScopedCounterStart& operator=(const ScopedCounterStart&) = delete;
};
/// The start of a pass's counters: a ScopedCounterStart's, else 0.
std::uint32_t counter_start();

/// The work-group size of a launch: `preferred` (a power of two) when the device
/// (CL_DEVICE_MAX_WORK_GROUP_SIZE, CL_DEVICE_MAX_WORK_ITEM_SIZES[0]) and the built kernel
/// (CL_KERNEL_WORK_GROUP_SIZE) allow it, else the largest power of two they allow (at least 1;
/// a limit of 0 counts as none).
std::size_t work_group_size(std::size_t preferred, std::size_t device_max, std::size_t item_max,
                            std::size_t kernel_max);

/// Host bytes per pixel of an accumulation (double sums and sums of squares, 3 + 3, and a sample
/// count: Accumulation, a part's sums) and of a RenderResult's images (mean and variance as
/// floats, 3 + 3, and the counts).
constexpr std::uint64_t kAccumulationPixelBytes = 6 * sizeof(double) + sizeof(std::uint32_t);
constexpr std::uint64_t kResultPixelBytes = 6 * sizeof(float) + sizeof(std::uint32_t);

/// One part of an estimate: what it is, its size, and what to reduce when it is too large.
struct MemoryPart {
  std::string what;  ///< "film accumulation (16384x16384)", "texture texels", ...
  std::uint64_t bytes = 0;
  std::string reduce;  ///< "the film size", ...
};

/// The parts' bytes together, saturated at the largest count (sys::bytes_add) rather than wrapped.
std::uint64_t total_bytes(const std::vector<MemoryPart>& parts);

/// What rendering `scene` will allocate on the host, estimated before packing: the film's
/// accumulation and result images, the scene description (`description_copies` of it: 2 where
/// the application keeps its own beside the session's copy, 1 where the session took it), the
/// packed triangles, spheres and texels, the BVH (its build and the tree), and per device the pass
/// read-back (and, for devices whose memory is the host's, their buffers). `devices` lists the
/// limits of each device of the session.
std::vector<MemoryPart> estimate_host_memory(const Scene& scene,
                                             const std::vector<DeviceLimits>& devices,
                                             int description_copies = 2);

/// The application's part of an estimate: what it declared it holds beside the session
/// (SessionOptions::reserved_host_bytes; none when 0).
std::vector<MemoryPart> reserved_part(std::uint64_t reserved, const std::string& what = "");

/// Throws lucent::Error when the estimate, with `extra` parts, exceeds `host_limit` (0: no
/// check), naming the largest part and the limit (80% of `limit_what`). Without `devices` (not
/// chosen yet) the estimate leaves their buffers out, and the error says "at least".
void check_host_memory(const Scene& scene, const std::vector<DeviceLimits>& devices,
                       std::uint64_t host_limit, const std::string& limit_what = "physical memory",
                       const std::vector<MemoryPart>& extra = {}, int description_copies = 2);

/// Before pack_scene outside a render (lucent info, Python's scene_info): throws lucent::Error as
/// check_host_memory does when the packed scene and its BVH, beside the description, exceed
/// host_memory_allowed() (info built 6.9M triangles' BVH past the limit, then said only "out of
/// memory", where render refused at once). `description_copies`: the scene descriptions held
/// (Python's scene_info packs a copy of the caller's: 2).
void check_packing_host_memory(const Scene& scene, int description_copies = 1);

/// What the scene description's arrays hold on the host (their capacities), in bytes.
std::uint64_t description_bytes(const Scene& scene);

/// Before rendering, for a front end that writes its outputs after the session (which took the
/// scene: set_scene(Scene&&)) is gone: throws lucent::Error as check_host_memory does, naming
/// `scene`, when `outputs` (what writing keeps and allocates) exceed host_memory_allowed().
void check_output_host_memory(const Scene& scene, const std::vector<MemoryPart>& outputs);

/// Before the CPU reference (render_reference) allocates: its accumulation and result images, the
/// scene's BVH, and with caustics one set of light sums per thread (`threads`), against
/// host_memory_limit() (lowered by a ScopedLimitOverride's host_mem). Throws lucent::Error as
/// check_host_memory does.
void check_reference_host_memory(const Scene& scene, int threads);

/// What lucent allows itself on the host: host_memory_limit(), lowered by a
/// ScopedLimitOverride's host_mem (0: unknown); `what` (when given) receives what the limit is
/// 80% of ("physical memory", ...), for messages.
std::uint64_t host_memory_allowed(std::string* what = nullptr);

/// An adaptive render's host memory beyond a uniform render's (session.cpp run_adaptive): the
/// halves A, B and C (sums and sums of squares, counts, launched samples, plans), A's and B's
/// pilots, the planner's per-pixel temporaries, and with caustics A's and B's light sums.
std::uint64_t adaptive_host_bytes(std::uint64_t npix, bool caustics);

/// check_host_memory with an adaptive render's memory added (adaptive_host_bytes).
void check_adaptive_host_memory(const Scene& scene, const std::vector<DeviceLimits>& devices,
                                bool caustics, std::uint64_t host_limit,
                                const std::string& limit_what = "physical memory",
                                const std::vector<MemoryPart>& extra = {},
                                int description_copies = 2);

/// The film buffers of a device: the pass's sums and sums of squares (double4 per pixel with
/// `fp64`, else float4), the work list (uint4 per pixel), and the light paths' sums and sums of
/// squares (two films with `caustics`, one element without; double4 with `light_double`, else
/// float4).
std::vector<MemoryPart> film_device_buffers(int width, int height, bool caustics, bool fp64,
                                            bool light_double);

/// Before upload: every scene buffer of `packed` (by its LC_SCENE_BUFFERS description) and film
/// buffer must fit in one allocation of the device, and all of them in its global memory.
/// Throws lucent::Error naming the buffer (the largest over the limit), its size, the device and
/// its limit.
void check_device_memory(const Scene& scene, const PackedScene& packed, const DeviceLimits& limits);

/// What a session is doing when OpenCL fails, for the advice of resource_error.
enum class ClStage {
  Upload,  ///< set_scene: creating and writing buffers (and the warm-up launch)
  Pass     ///< a pass: its launch, or its read-back when the failing call is a clEnqueueRead*
};

/// A cl::Error thrown while `stage` on `device`, as one line: CL_OUT_OF_RESOURCES,
/// CL_MEM_OBJECT_ALLOCATION_FAILURE and CL_OUT_OF_HOST_MEMORY say what ran out and what to reduce;
/// other errors keep cl_util::describe's text.
std::string resource_error(const cl::Error& e, ClStage stage, const std::string& scene_path,
                           const std::string& device);

}  // namespace lucent::render_detail
