#pragma once
// Convergence studies: render a ladder of sample counts (or time budgets) for several speed and
// accuracy settings, measure each render's error against a reference image, fit the rate at which
// the error falls and tell biased settings (error that stops falling) from unbiased ones.
// `lucent converge` is the front end; BENCHMARKS.md ("Convergence") shows a run.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "lucent/image.hpp"
#include "lucent/render.hpp"
#include "lucent/scene.hpp"

namespace lucent {

/// One speed/accuracy setting: knobs applied on top of the scene and the render options.
/// Syntax (parse_converge_setting): knobs joined by '+', e.g. "max_depth=2+fast-math".
///   default            the scene as it is
///   fast-math          RenderOptions::fast_math
///   double / float     RenderOptions::precision (precision=double|float also accepted)
///   no-specialize      RenderOptions::specialize = false
///   no-mis / mis       integrator.mis off / on
///   max_depth=N        integrator.max_depth (N >= 1)
///   rr_depth=N         integrator.rr_depth (N >= 1)
///   filter=TYPE[:R]    film.filter: a filter name (box, tent, gaussian: lucent/types.hpp),
///                      optional radius R in pixels, in (0, limits::kMaxFilterRadius]
///   integrator=NAME    an integrator or AOV name (path, whitted, ..., primitive)
///   sampler=NAME       integrator.sampler: sobol or independent
///   clamp=X            integrator.clamp (X >= 0; 0: off)
///   caustics / no-caustics  integrator.caustics on / off
///   splits=N           integrator.dielectric_splits (0 .. limits::kMaxDielectricSplits)
///   adaptive           each rung an adaptive render (Renderer::render_adaptive) whose samples
///                      average the rung's spp; rungs below the pilot are skipped
///   min-spp=N          adaptive: the pilot's samples per pixel (default 64)
///   target-error=E     one adaptive render to relMSE E (E > 0), whatever the ladder
/// The setting's name is the text it was parsed from.
struct ConvergeSetting {
  std::string name = "default";
  bool fast_math = false;
  int precision = -1;  ///< -1: the options'; else a Precision
  bool specialize = true;
  int mis = -1;              ///< -1: the scene's; 0 off; 1 on
  int max_depth = 0;         ///< 0: the scene's
  int rr_depth = 0;          ///< 0: the scene's
  int filter = -1;           ///< -1: the scene's; else a FilterType
  double filter_radius = 0;  ///< 0: the scene's (or the filter's default when the type changes)
  int integrator = -1;       ///< -1: the scene's; else an IntegratorType
  int sampler = -1;          ///< -1: the scene's; else a SamplerType
  double clamp = -1;         ///< < 0: the scene's; else integrator.clamp
  int caustics = -1;         ///< -1: the scene's; 0 off; 1 on (integrator.caustics)
  int splits = -1;           ///< -1: the scene's; else integrator.dielectric_splits
  bool adaptive = false;     ///< rungs are adaptive renders of the rung's mean spp
  int min_spp = 0;           ///< adaptive: the pilot (0: AdaptiveOptions' default)
  double target_error = 0;   ///< > 0: one adaptive render to this relMSE

  /// Applies the setting to a copy of the scene and of the options.
  void apply(Scene& scene, RenderOptions& options) const;
};

/// Parses one setting (syntax above). Throws lucent::Error naming the knob that is wrong.
ConvergeSetting parse_converge_setting(const std::string& text);

/// Parses a list of settings, refusing one given twice however it is spelt ("max_depth=3" and
/// "max-depth=3", "clamp=1" and "clamp=1.0": the same renders twice). Throws lucent::Error.
std::vector<ConvergeSetting> parse_converge_settings(const std::vector<std::string>& texts);

/// One rung of the ladder: one render of one setting, compared with the reference.
struct ConvergePoint {
  std::string setting;
  std::uint64_t spp = 0;          ///< samples per pixel rendered
  double seconds = 0;             ///< render time (RenderResult::seconds, kernel build excluded)
  double samples_per_second = 0;  ///< camera samples (all pixels) per second
  double rays_per_second = 0;
  double rmse = 0;    ///< as compare_images(): sqrt(mean (A - R)^2)
  double relmse = 0;  ///< as compare_images(): mean (A - R)^2 / (R^2 + 0.01)
  /// The relMSE that noise alone explains: mean over pixel-channels of (var_A / n_A + var_R /
  /// n_R) / (R^2 + 0.01), from the per-pixel sample variances of the render and the reference.
  /// The expected relMSE of an unbiased setting of independent samples (Sobol's stratified
  /// samples err less: for them it is an upper bound); 0 when the render has fewer than 2 samples
  /// per pixel (no variance estimate).
  double noise_relmse = 0;
  /// The reference's own share of noise_relmse: mean over pixel-channels of var_R / n_R /
  /// (R^2 + 0.01) (0 without its variance); its expected contribution to relmse.
  double reference_noise_relmse = 0;
  /// The standard error of relmse - noise_relmse where the setting is unbiased, from the spread
  /// of the pixels' terms ((A - R)^2 - var_A / n_A - var_R / n_R) / (R^2 + 0.01), the three
  /// channels of a pixel summed as one (0 without a variance estimate). Large where a few pixels
  /// hold the error (rare bright samples, a heavy-tailed estimate), small where a bias spreads.
  double excess_standard_error = 0;
  /// Adaptive renders: the relMSE the render's own variances predict (RenderResult).
  double estimated_relmse = 0;
  /// Adaptive renders: the a-posteriori relMSE from the halves' difference (RenderResult).
  double halves_relmse = 0;
};

/// The error curve of one setting, fitted on log-log axes.
struct ConvergeFit {
  std::string setting;
  std::size_t points = 0;
  // The slopes are NaN when the points hold fewer than two different spp (one rung, a
  // repeated one, a target-error setting's single render).
  double slope_time = 0;      ///< least-squares slope of log(relMSE) against log(seconds)
  double slope_spp = 0;       ///< least-squares slope of log(relMSE) against log(spp)
  double tail_slope_spp = 0;  ///< the same over the last three rungs (flattens when biased)
  /// relMSE / noise_relmse at the last rung: about 1 when the error is all noise.
  double excess_ratio = 0;
  /// Biased: at the last rung the error exceeds what the noise explains by more than 30%
  /// (kBiasRatio), i.e. the squared bias is over 0.3 x the variance and the curve is turning flat
  /// towards it. (Without a variance estimate, a tail slope flatter than -0.5 decides.) An
  /// unbiased setting stays near 1: the measured error and the variance estimate come from the
  /// same samples, over every pixel-channel.
  static constexpr double kBiasRatio = 1.3;
  /// ... and the excess is significant: over kBiasSigmas standard errors
  /// (ConvergePoint::excess_standard_error). An unbiased path tracer of the Cornell box at 32x32,
  /// 64 spp, was "biased" for 2 seeds of 15 (error/noise 1.4-1.6: a few pixels' rare bright
  /// paths), against a reference of 16 times the samples. An excess above kBiasRatio that is not
  /// significant is "undetermined": a few pixels hold it, and k biased pixels score about
  /// sqrt(k) standard errors whatever their bias, as rare bright samples in them would.
  static constexpr double kBiasSigmas = 3;
  /// run_convergence adds to the verdict that it is unreliable when the reference's own noise is
  /// above this share of noise_relmse at the last rung (a reference about as noisy as the rung:
  /// relMSE divides by its noisy values), and, for an unbiased verdict on Sobol samples, that
  /// their noise estimate runs above their error (a bias can hide under it).
  static constexpr double kReferenceShare = 1.0 / 3.0;
  bool biased = false;
  double bias_relmse = 0;  ///< relMSE - noise_relmse at the last rung: the floor
  /// Render time at which the render's own noise (noise_relmse less reference_noise_relmse at
  /// the last rung, extrapolated as 1/t) falls below the floor: where the error stops
  /// decreasing. 0 when not biased.
  double floor_seconds = 0;
  std::string verdict;  ///< one line, e.g. "unbiased" or "biased: error stops decreasing at ..."
};

/// Fits one setting's points (in ladder order). Needs at least two points for the slopes.
ConvergeFit fit_convergence(const std::vector<ConvergePoint>& points);

class Renderer;

struct ConvergeOptions {
  std::vector<ConvergeSetting> settings;  ///< empty: {default}
  /// Samples per pixel of each rung, rendered (and its points given) in ascending order.
  std::vector<int> spp_ladder;
  std::vector<double> time_ladder;  ///< seconds per rung, as spp_ladder; used instead if set
  /// Device, kernel and cache directories, pass_seconds, cancel, on_progress (spp and time are
  /// the ladder's; precision, fast math and specialisation the settings').
  RenderOptions render;
  /// The session to render with (its device, kernel and cache directories); null: a session
  /// opened from `render`. Either way one session renders every rung of every setting. A session
  /// given here ends with the last setting's scene, build options and accumulation; its cancel
  /// flag is `render.cancel` during the study (when set) and its own again afterwards. Its
  /// cancel() (or the flag) stops the study after the current pass, or before the next rung when
  /// asked for between two; the result has the points of the rungs finished. A session busy
  /// with another call (another thread's render, or the study started from a render's
  /// on_progress) is refused before anything changes: lucent::Error naming run_convergence, the
  /// render's cancel() and cancel flag untouched.
  Renderer* renderer = nullptr;
  /// Called after each rung (progress output). It may read the study's session (result(),
  /// spp(), stats()) and cancel() it; a call that changes it (set_scene, render, reset,
  /// set_build_options) throws lucent::Error, which ends the study.
  std::function<void(const ConvergePoint&)> on_point;
};

struct ConvergeResult {
  std::vector<ConvergePoint> points;  ///< setting by setting, each in ascending rung order
  std::vector<ConvergeFit> fits;      ///< one per setting, in the order given
};

/// Checks a study's ladder and settings before anything is rendered (run_convergence does it
/// too): an empty ladder, an spp below 1 or a time not above 0, an adaptive or target-error
/// setting with a time ladder, an adaptive setting whose pilot (min-spp, default
/// AdaptiveOptions::min_spp) is above every rung (it would render nothing); with `scene`, a
/// setting's knob that its integrator does not read (clamp, caustics, splits, mis and rr_depth:
/// path only; max_depth: path and whitted). Throws lucent::Error.
void check_convergence_options(const ConvergeOptions& options, const Scene* scene = nullptr);

/// Renders every setting at every rung and compares each render with `reference` (which must
/// have the scene's film size; its variance and samples may be empty; a lucent render, whose
/// `sampler` is set, must not have the scene's seed: see reference_seed()). Throws lucent::Error.
ConvergeResult run_convergence(const Scene& scene, const RenderResult& reference,
                               const ConvergeOptions& options);

/// The seed a reference render should use so that its random numbers are independent of the
/// ladder's (the scene's seed would replay the ladder's samples and hide their error).
std::uint32_t reference_seed(std::uint32_t scene_seed);

/// Powers of two from 1 to max_spp (max_spp included when it is not a power of two).
std::vector<int> default_spp_ladder(int max_spp);

/// The samples per pixel of the reference `lucent converge` renders for a ladder: 16 times its
/// top rung, at least 256 and at most 2^24 (limits::kMaxSpp; a top rung past 2^20 asked for up
/// to 2^28); 1024 for a time ladder (`spp_ladder` empty).
int default_reference_spp(const std::vector<int>& spp_ladder);

/// CSV: setting,spp,seconds,samples_per_s,rmse,relmse,noise_relmse,rays_per_s,
/// reference_noise_relmse,estimated_relmse,halves_relmse; one row a point.
std::string convergence_csv(const ConvergeResult& result);

/// The render time at which one setting's points (in ladder order) reach relMSE `error`,
/// interpolated linearly on log-log axes between the rungs around the first crossing; the first
/// rung's time when it is already below; infinity when no rung reaches it.
double time_to_relmse(const std::vector<ConvergePoint>& points, double error);

/// SVG: relMSE against render time on log-log axes, one path (with point markers) per setting,
/// axis labels, decade ticks and a legend.
std::string convergence_svg(const ConvergeResult& result, const std::string& title);

/// The same plot as a linear RGB image (write it with write_image(), e.g. as a PNG).
Image convergence_image(const ConvergeResult& result, const std::string& title);

}  // namespace lucent
