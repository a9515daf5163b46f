#pragma once
// A render session: one device (and its kernel builds) and one scene, rendered progressively.
//
//   lucent::Renderer renderer(lucent::SessionOptions::from_environment());
//   renderer.set_scene(lucent::load_scene("scenes/default.json"));
//   renderer.render(64);                        // adds 64 samples per pixel
//   lucent::RenderResult r = renderer.result();
//   lucent::Camera camera = renderer.scene().camera;
//   camera.position.x += 1;                     // a new camera: nothing packed or built again
//   renderer.set_camera(camera);
//   renderer.render_for(2.0);                   // about two seconds of samples
//
// set_scene() packs the scene and builds what it needs, reusing what it can: the BVH when the
// geometry is unchanged, the kernel when its build options are (they change with the types the
// scene uses and the session's precision and math mode), the device buffers whose contents are
// unchanged. set_camera() changes the camera alone without packing the scene again (a camera
// move of a large scene: an interactive viewer, a turntable). stats() counts what was built.
// No OpenCL type appears in this header.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "lucent/accumulation.hpp"
#include "lucent/device.hpp"
#include "lucent/render.hpp"
#include "lucent/scene.hpp"

namespace lucent {

namespace render_detail {
class CancelScope;  // src/render/cancel_scope.hpp
}  // namespace render_detail

/// How a session is set up. Every field has a built-in default; the environment is consulted
/// only through from_environment().
struct SessionOptions {
  /// Device selector: an index from list_devices() or a case-insensitive substring of a device
  /// name; "" picks the first GPU, else the first CPU device. Several devices: a comma-separated
  /// list of selectors ("0,2", "nvidia,pthread"), or "all" for every device; they share each
  /// render's passes (each device takes the next pass when it is done, its pass size tuned to its
  /// speed) into one accumulation. A device listed twice opens two contexts on it.
  std::string device;
  /// Kernel sources: "" uses the copy embedded in the library; a directory loads kernels/ files
  /// from there instead (kernel development without rebuilding).
  std::string kernel_dir;
  /// Directory of the kernel binary cache; "" means $XDG_CACHE_HOME/lucent or ~/.cache/lucent,
  /// "off" disables the cache. Its size limit is LUCENT_CACHE_MAX_MB's (default 256 MiB; README).
  std::string cache_dir;
  Precision precision = Precision::Float;  ///< Double: rays and geometry in double (needs fp64)
  bool fast_math = false;                  ///< -cl-fast-relaxed-math (default: IEEE math)
  bool specialize = true;                  ///< compile only the features the scene uses
  double pass_seconds = 0.25;              ///< target duration of one kernel launch
  /// Host memory the application holds beside the session while the session lives (an output
  /// being written, another result kept), in bytes: added to the estimate by which set_scene and
  /// render_adaptive refuse, before rendering, a film too large for the host's memory, so that a
  /// render is not lost to its write. `lucent render` declares its outputs here.
  std::uint64_t reserved_host_bytes = 0;
  /// What reserved_host_bytes holds, for the error that refuses a film (empty: "what the
  /// application keeps beside the session (its outputs, as it declared them)").
  std::string reserved_host_what;
  /// Warnings of scene packing (skipped triangles, ...); null: to the calling thread's
  /// ScopedWarningSink (lucent/warnings.hpp), else "lucent: warning: ..." on stderr.
  /// A session gives each warning about its scenes once, however often set_scene meets it.
  WarningSink on_warning;

  /// The defaults of the `lucent` command: device from LUCENT_DEVICE, kernel directory from
  /// LUCENT_KERNEL_DIR, cache directory from LUCENT_CACHE_DIR (each when set and not empty).
  static SessionOptions from_environment();
};

/// What a session has built and done, for tools that want to know what a change cost.
/// scene_packs, bvh_builds and kernel_reuses count set_scene() calls (set_build_options() with a
/// scene makes one, and so does a set_camera() that cannot keep the kernel); camera_moves counts
/// set_camera() calls that packed nothing; the other counters and the times count work on the
/// devices, summed over the session's devices: with two devices a new program is two builds, a
/// buffer written is written to each (two uploads), and each device's passes count.
struct SessionStats {
  std::uint64_t scene_packs = 0;         ///< set_scene() calls that packed a scene
  std::uint64_t bvh_builds = 0;          ///< BVH builds (not counted when the geometry was reused)
  std::uint64_t kernel_compiles = 0;     ///< kernel programs compiled from source, per device
  std::uint64_t kernel_cache_loads = 0;  ///< programs loaded from the binary cache, per device
  /// set_scene() calls that kept the session's program: no device built or loaded one (one per
  /// call, whatever the number of devices)
  std::uint64_t kernel_reuses = 0;
  /// set_camera() calls that changed the camera without packing the scene (no scene_packs)
  std::uint64_t camera_moves = 0;
  /// scene buffers written to each device: the first set_scene writes every buffer that holds
  /// data (an empty one is not counted), a later one the buffers whose contents changed
  std::uint64_t buffer_uploads = 0;
  std::uint64_t bytes_uploaded = 0;  ///< the bytes of those buffers
  std::uint64_t passes = 0;          ///< kernel launches that rendered samples
  double pack_seconds = 0;           ///< packing, BVH included
  double bvh_seconds = 0;
  double build_seconds = 0;   ///< kernel builds and cache loads
  double render_seconds = 0;  ///< kernel passes (each device's time: they overlap)
};

/// An adaptive render (Renderer::render_adaptive; docs/rendering-model.md, "Adaptive sampling"):
/// a pilot of min_spp samples in every pixel, then more samples where the pixel's error is high,
/// planned so that the image's estimated relMSE (as lucent compare defines it) reaches
/// target_error, or so that the samples average budget_spp per pixel. Unbiased: the samples are
/// kept in two independent halves, each planned from the other's pilot (src/render/adaptive.hpp).
/// With a target error, the pilot is rendered without glass splitting
/// (integrator.dielectric_splits), the samples after it with the scene's splits.
struct AdaptiveOptions {
  double target_error = 0;        ///< relMSE to reach (> 0); 0: use budget_spp
  double budget_spp = 0;          ///< instead of a target: the mean samples per pixel
  std::uint32_t min_spp = 64;     ///< per pixel: the pilot (even, >= 4; half in each half)
  std::uint32_t max_spp = 16384;  ///< per pixel, at most
  double max_seconds = 0;         ///< stop after this much time (0: no limit)
};

/// One device and one scene, rendered progressively. One call at a time: a render, set_scene,
/// set_camera, reset or set_build_options made during another of them (from a callback, or
/// another thread) throws lucent::Error. cancel() may be called at any time, from any thread; a
/// render's on_progress may read result(), spp() and stats(). Other uses from several threads
/// are not supported.
class Renderer {
 public:
  /// Opens the device. Throws lucent::Error (no device, unknown selector, ...).
  explicit Renderer(SessionOptions options = {});
  /// Destroying a session during one of its own calls (from its on_progress, or from
  /// run_convergence's on_point on it) ends the process with a line on stderr (the call would
  /// go on in freed memory).
  ~Renderer();
  /// Moves the session. Throws lucent::Error during a render of either session (from its
  /// on_progress: the render would go on in a session moved away or destroyed).
  Renderer(Renderer&&);
  Renderer& operator=(Renderer&&);
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// The (first) device, and all of them.
  const DeviceInfo& device() const;
  std::vector<DeviceInfo> devices() const;
  const SessionOptions& options() const;
  /// Changes the build settings (precision, fast math, specialisation) for the next render; the
  /// device, kernel directory and cache directory stay those the session was opened with.
  void set_build_options(Precision precision, bool fast_math, bool specialize);

  /// Makes `scene` the session's scene (a copy is kept): packs it, builds or reuses the BVH and
  /// the kernel, uploads the buffers that changed. The accumulated samples are kept when nothing
  /// that changes the image changed (film display settings, the sample count), and dropped
  /// otherwise (the next sample index is then the last reset()'s first_sample, 0 by default).
  /// Throws lucent::Error for a scene it cannot render, first checking the whole scene
  /// as SceneBuilder checks each element (its fields may have been set directly), with the place
  /// of the first problem ("scene.json: /shapes/1 (triangle 4)/v/2: must index one of ..."),
  /// except where it allows more: a film of any size from 1 (the host and device memory checks
  /// bound it, not limits::kMaxImageSize), materials of any names (the scene's references are
  /// indices), and spheres or positions that are not finite (never hit; a warning).
  void set_scene(const Scene& scene);
  /// set_scene() that takes the scene instead of copying it: its arrays (a large mesh's
  /// vertices, a texture's texels) are then held once, by the session, not also by the caller.
  /// On success `scene` is left empty (read it back with scene()); when this throws, `scene` is
  /// untouched.
  void set_scene(Scene&& scene);
  /// Moves the camera of the session's scene: what set_scene() of that scene with `camera`
  /// does (the same image, bit for bit; the same errors, at "/camera"; its warnings, each once per
  /// session; the accumulation dropped unless the camera is the same), without packing the scene
  /// again: the camera is packed into the launch parameters, and on a scene lit by an environment
  /// the light table is built again when the camera's distance to its look-at changes it (a few
  /// lights, the environment map's texel CDF); nothing else is packed, built or uploaded
  /// (stats().camera_moves counts such calls). Falls back to a whole set_scene() (counted as one)
  /// where it cannot: a camera that changes the kernel (an aperture from or to 0 with
  /// specialisation: the lens code), or after a set_scene() or set_camera() that failed part-way
  /// and left the devices without a scene (render() refuses until a call succeeds). A set_scene()
  /// refused before it changed the devices (a bad scene) leaves the previous scene, whose camera
  /// this moves as any other. The film, integrator and everything else stay the scene's: change
  /// them through set_scene() (a film size also changes the session's buffers). Throws
  /// lucent::Error without a scene, for an invalid camera (the session unchanged) or during a
  /// render.
  void set_camera(const Camera& camera);
  /// The session's scene. Throws lucent::Error when none was set.
  const Scene& scene() const;

  /// Adds `spp` samples per pixel to the accumulation (fewer when cancelled); throws
  /// lucent::Error when they would pass sample index 2^32 (the sampler's range) or 2^32 - 1
  /// samples per pixel in the accumulation (its 32-bit counts). `on_progress` is
  /// called after each pass; it may read the session (result(), spp(), stats()) and cancel() it,
  /// while set_scene, set_build_options, reset and the render calls throw lucent::Error until the
  /// render returned. Returns the progress at the end.
  RenderProgress render(std::uint64_t spp,
                        const std::function<void(const RenderProgress&)>& on_progress = {});
  /// Adds samples for about `seconds` (at least one pass, but none when cancelled with samples
  /// accumulated: set_cancel_flag).
  RenderProgress render_for(double seconds,
                            const std::function<void(const RenderProgress&)>& on_progress = {});
  /// Adds `spp` samples per pixel or samples for `max_seconds`, whichever comes first (0: no
  /// limit of that kind; not both 0).
  RenderProgress render(std::uint64_t spp, double max_seconds,
                        const std::function<void(const RenderProgress&)>& on_progress = {});
  /// Renders adaptively (AdaptiveOptions): a pilot, then the samples planned from it, until the
  /// plan is done, the time limit or a cancel. A further call continues the same render with
  /// another target or budget (a plan never takes samples away), so a series of rising budgets
  /// is progressive; calling it on a uniform accumulation that has samples, or render() on an
  /// adaptive one, throws lucent::Error: reset() first. result() gives the average of the halves,
  /// with per-pixel counts and a variance such that var / n is the variance of the pixel's mean;
  /// RenderResult::spp is the samples launched per pixel on average, the calibration stream's
  /// (a target's, on a sparse grid, never in the image) included: the render's cost. The mean of
  /// RenderResult::samples is the image's.
  RenderProgress render_adaptive(
      const AdaptiveOptions& options,
      const std::function<void(const RenderProgress&)>& on_progress = {});
  /// Drops the accumulation (uniform or adaptive); the next sample index is `first_sample`
  /// (sample ranges: a render of samples [A, B) is reset(A) then render(B - A)).
  void reset(std::uint64_t first_sample = 0);

  /// The accumulation so far: per-pixel mean, sample variance and sample count, with the spp,
  /// rays, non-finite samples and render time. Cheap enough to call after every pass.
  RenderResult result() const;
  /// Samples per pixel accumulated so far.
  std::uint64_t spp() const;
  /// Index of the first sample of the accumulation (reset's argument).
  std::uint64_t first_sample() const;
  /// The raw accumulation (double sums, sums of squares, counts) of the samples
  /// [first_sample(), first_sample() + spp()), for sample-range renders (lucent/parts.hpp). Throws
  /// lucent::Error for an adaptive render (render_adaptive).
  Accumulation accumulation() const;
  /// A 64-bit hash of everything the image depends on: the packed scene (camera, film size and
  /// filter, seed, integrator settings, geometry, materials, lights, textures) and the kernel's
  /// build options. Renders of equal hashes give the same samples for the same sample indices.
  std::uint64_t image_hash() const;

  /// Stops a render in progress after its current pass (callable from another thread or a
  /// signal handler through set_cancel_flag). A cancel asked for while no render runs is dropped
  /// when the next one starts, but during a convergence study on this session
  /// (ConvergeOptions::renderer), which it stops, between two rungs too.
  void cancel();
  /// An external flag checked before each pass, as cancel() (e.g. set by a SIGINT handler). A
  /// render that starts with the flag raised still renders one pass when the accumulation holds
  /// no sample yet (with samples, none): check the flag before calling to render nothing, as
  /// `lucent render` does after set_scene.
  void set_cancel_flag(const std::atomic<bool>* flag);
  /// The flag set_cancel_flag gave (null: none).
  const std::atomic<bool>* cancel_flag() const;

  SessionStats stats() const;

 private:
  friend class render_detail::CancelScope;
  struct Impl;
  /// The session; throws lucent::Error on a moved-from Renderer.
  Impl& impl() const;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lucent
