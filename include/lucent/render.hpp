#pragma once
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "lucent/image.hpp"
#include "lucent/scene.hpp"
#include "lucent/warnings.hpp"

namespace lucent {

/// One device's part of a render (several devices share a render's passes).
struct DeviceShare {
  std::string device;         ///< the device's name
  std::uint64_t samples = 0;  ///< samples per pixel it rendered
  double seconds = 0;         ///< time its passes took
};

struct RenderProgress {
  std::uint64_t samples_done = 0;    ///< per pixel, by this render call
  std::uint64_t samples_target = 0;  ///< per pixel (0 when only a time limit is set)
  std::uint64_t accumulated = 0;     ///< per pixel, in the accumulation (earlier calls included)
  double elapsed = 0;                ///< seconds
  double time_limit = 0;             ///< seconds (0: none)
  double samples_per_second = 0;     ///< camera samples (all pixels) per second
  std::vector<DeviceShare> devices;  ///< each device's part of this render call
};

/// Arithmetic of rays and geometry in the kernel (docs/rendering-model.md, "Precision"): float,
/// or double on devices with fp64 (radiance, BSDFs, textures and buffers stay float).
enum class Precision { Float, Double };

/// "float" or "double"; throws lucent::Error for a value outside the enum.
const char* precision_name(Precision p);

/// Parses "float" or "double"; throws lucent::Error naming `what` (e.g. "--precision") otherwise.
Precision parse_precision(const std::string& text, const std::string& what = "--precision");

/// Options of the one-shot render() (a session's options, SessionOptions, plus the sample budget).
struct RenderOptions {
  std::string device;      ///< selector, see select_device()
  std::string kernel_dir;  ///< "" : embedded kernel sources (see SessionOptions)
  std::string cache_dir;   ///< "" : the default cache directory; "off": none
  WarningSink on_warning;  ///< null: the thread's ScopedWarningSink, else stderr
  int spp = 0;             ///< 0: the scene's integrator.spp, or with a time_limit unbounded
  double time_limit = 0;   ///< seconds; 0: none
  const std::atomic<bool>* cancel = nullptr;  ///< set to stop after the current pass
  std::function<void(const RenderProgress&)> on_progress;
  double pass_seconds = 0.25;  ///< target duration of one launch
  bool fast_math = false;      ///< build with -cl-fast-relaxed-math (default: IEEE math)
  bool specialize = true;      ///< compile only the features the scene uses (false: all)
  Precision precision = Precision::Float;  ///< Double: build with -D LC_DOUBLE (needs fp64)
  /// > 0: render adaptively until the image's estimated relMSE is at most this
  /// (Renderer::render_adaptive), with at least min_spp and at most `spp` samples per pixel (0:
  /// AdaptiveOptions' defaults) and the time limit.
  double target_error = 0;
  int min_spp = 0;  ///< adaptive: the pilot per pixel; 0: AdaptiveOptions' default
};

/// integrator.caustics: the light-traced part of the image mean (the mean over the N pixels, per
/// channel), for compare's image-mean test (docs/compare.md, "The test"). A light path splats
/// into many pixels, so the pixels' light parts are correlated: `paths` is that part's variance
/// from each light path's total (its shares summed over all pixels, over N) taken as one sample,
/// var(total) / paths; `pixels` is what the variance layer holds of it, the light part's variance
/// of each pixel's mean summed over the pixels as if they were independent, over N^2, over the
/// pixels of n >= 2 only (compare reads a pixel of n < 2 as variance 0). The image mean's
/// variance is then sum(var / n) / N^2 - pixels + paths. write_render_exr stores both
/// (the attribute lucent.light_mean_var) and read_render reads them back.
struct LightMeanVariance {
  double paths[3] = {0, 0, 0};
  double pixels[3] = {0, 0, 0};
};

struct RenderResult {
  Image mean;                          ///< per-pixel mean radiance
  Image variance;                      ///< per-pixel sample variance (of one sample)
  std::vector<std::uint32_t> samples;  ///< finite samples per pixel
  std::uint64_t spp = 0;               ///< samples per pixel launched (adaptive: the mean,
                                       ///< calibration samples included; see render_adaptive)
  std::uint64_t nonfinite = 0;         ///< NaN/Inf samples dropped and counted
  std::uint64_t rays = 0;              ///< rays traced, shadow rays included
  double seconds = 0;                  ///< rendering time (kernel passes)
  double build_seconds = 0;            ///< kernel source assembly and build (or cache load) time
  bool program_cache_hit = false;      ///< the program came from lucent's binary cache
  std::string build_options;           ///< OpenCL build options, feature defines included
  bool cancelled = false;
  std::string device;                ///< the device's name ("A + B" for several)
  std::vector<DeviceShare> devices;  ///< each device's part of the accumulation
  /// Adaptive renders: the relMSE that the image's own per-pixel variances predict (mean over
  /// pixel-channels of var / n / (value^2 + 0.01), value the smaller of the pixel's mean and its
  /// neighbours'), each half's share scaled by its model_gain when the render had a target, and
  /// the target; 0 for uniform renders.
  double estimated_relmse = 0;
  double target_error = 0;
  /// Adaptive renders: the a-posteriori relMSE from the difference of the two halves (mean over
  /// pixel-channels of (A - B)^2 / 4 / (value^2 + 0.01), value as above), an estimate of the
  /// error variance for any sampler, Sobol included (noisy on small films); 0 for uniform renders.
  double halves_relmse = 0;
  /// Adaptive renders with a target: the calibration's gains of halves A and B (measured error of
  /// a pilot over the v / n model's; ~1 with independent samples, < 1 with Sobol; kept when a
  /// budget call continues the render, as estimated_relmse still uses them), and the relMSE the
  /// calibrated plans of the last call predicted (0 when that call had a budget); 0 otherwise.
  double model_gain_a = 0, model_gain_b = 0;
  double planned_relmse = 0;
  /// Adaptive renders: how far the last render_adaptive call got. planned_spp is the mean over
  /// pixels of the samples its plans ask for (calibration samples included, as spp): the pilot's
  /// while the pilot is not complete. pilot_incomplete: a time limit or a cancel stopped the render
  /// in its pilot, so no plan was made and the estimates above read a partial pilot (the halves'
  /// difference maybe none at all: 0). plan_incomplete: it stopped before every planned sample was
  /// rendered (in the pilot or after). 0 and false for uniform renders and complete ones.
  std::uint64_t planned_spp = 0;
  bool pilot_incomplete = false, plan_incomplete = false;
  /// The key of the render's random numbers: the scene's integrator seed and the sampler's name
  /// ("sobol", "independent"), set by the kernel and reference renderers; sampler "" when unknown
  /// (an image read from a file that does not say). write_render_exr stores both (lucent.seed,
  /// lucent.sampler) and read_render reads them back, so that `lucent converge` can refuse a
  /// reference rendered at its ladder's own seed.
  std::uint32_t seed = 0;
  std::string sampler;
  /// integrator.caustics: the light-traced part of the image mean's variance (LightMeanVariance);
  /// absent without caustics, and from images that do not carry it.
  std::optional<LightMeanVariance> light_mean_variance;
};

/// A render with a target error whose halves' estimate (halves_relmse) is above 1.5 times the
/// target (widened on small films by twice that estimate's relative noise, sqrt(2 / (3 pixels)):
/// 1.52 E at 128 x 128, 2.7 E at 2 x 2): one line saying so and what to do ("" otherwise, and
/// for renders without a target and cancelled ones). A render that a time limit stopped in its
/// pilot always gets one (no plan was made, nothing estimated); one it stopped later names the
/// time limit as the cause.
/// The plan is made from a pilot, and a pilot that misses a scene's rare bright paths
/// under-predicts (docs/rendering-model.md "Adaptive sampling"); the halves see what the whole
/// render drew. Not a failure: the image is unbiased, only noisier than asked.
std::string target_shortfall(const RenderResult& result);

/// Renders `scene` with the OpenCL megakernel: a one-shot lucent::Renderer session
/// (lucent/session.hpp) that stops at options.spp samples per pixel or after options.time_limit
/// seconds, whichever comes first. options.spp 0 is the scene's integrator.spp without a time
/// limit, and unbounded with one (as many samples as the time allows, as the CLI's --time without
/// --spp). With options.target_error, adaptively.
RenderResult render(const Scene& scene, const RenderOptions& options = {});

}  // namespace lucent
