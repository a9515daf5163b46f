#pragma once
// Subcommands beyond render and devices live in their own files and register here.
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "cli/option_checks.hpp"
#include "core/text.hpp"
#include "lucent/render.hpp"
#include "lucent/scene.hpp"
#include "lucent/session.hpp"
#include "render/integrator_knobs.hpp"
#include "scene/loaders.hpp"

namespace lucent::cli {

using io::one_line;

/// "path", "whitted", ... -> IntegratorType; throws lucent::Error on an unknown name.
IntegratorType parse_integrator(const std::string& name);

/// The command's defaults for a render: device, kernel directory and cache directory from
/// LUCENT_DEVICE, LUCENT_KERNEL_DIR and LUCENT_CACHE_DIR
/// (lucent::SessionOptions::from_environment).
RenderOptions render_options_from_environment();

/// Session options for a render: the environment's defaults, `device` (from --device) when not
/// empty. Checks the device selector first, so that an unknown one is reported as the
/// command's user gave it ("--device 'x': ..." or "LUCENT_DEVICE 'x': ...").
SessionOptions session_options(const std::string& device);

/// The kernel binary cache directory the command uses ("" when disabled: LUCENT_CACHE_DIR=off).
std::string cache_dir_from_environment();
/// The names --aov accepts: the registry's AOVs (albedo, normal, ...), then "variance".
std::vector<std::string> aov_names();

/// Checks for a real option, with one-line messages ("must be a positive number, got -1"):
/// CLI::PositiveNumber and NonNegativeNumber report a range up to 1.8e308 written out in full.
/// (NaN and infinities are refused before these run: main.cpp's non_finite_option.)
CLI::Validator positive_real();
CLI::Validator non_negative_real();
/// lo <= value <= hi, as "must be in [1e-12, 0.5], got 0" (CLI::Range prints "%f": 0.000000).
CLI::Validator real_range(double lo, double hi);
/// A time in seconds: in (0, lucent::limits::kMaxSeconds], "must be in (0, 1e7] seconds" (as
/// lucent-mpi's --time says it).
CLI::Validator seconds_limit();

/// "a, b, c".
std::string joined(const std::vector<std::string>& names);

using scene_detail::scene_inputs;

/// `lucent render` (cmd_render.cpp): registers the subcommand, runs it once parsed; the scene
/// path given, for messages.
CLI::App* add_render_command(CLI::App& app);
int run_render_command();
const std::string& render_scene();

/// The sampling options of `render` (and --sampler, --clamp of `info`): src/cli/sampling.cpp.
struct SamplingArgs {
  std::string sampler;      ///< "" : the scene's integrator.sampler
  double clamp = -1;        ///< < 0: the scene's integrator.clamp
  int caustics = -1;        ///< < 0: the scene's integrator.caustics; 0 off; 1 on
  int splits = -1;          ///< < 0: the scene's integrator.dielectric_splits
  double target_error = 0;  ///< > 0: adaptive sampling to this relMSE
  int min_spp = 0;          ///< adaptive: the pilot (0: the default)
};
/// Adds --sampler and --clamp (and, with `adaptive`, --target-error and --min-spp) to `cmd`.
void add_sampling_options(CLI::App* cmd, SamplingArgs& args, bool adaptive);
/// Applies --sampler and --clamp to the scene.
void apply_sampling_options(const SamplingArgs& args, Scene& scene);

/// When `given`, refuses `option` (as the command line names it) if the scene's integrator does
/// not read `knob`: "--clamp: only the path integrator has it, and this render's is albedo".
void check_knob(const Scene& scene, bool given, render_detail::IntegratorKnob knob,
                const char* option);
/// The adaptive render of --target-error: --min-spp, --spp as the maximum, --time.
AdaptiveOptions adaptive_options(const SamplingArgs& args, int max_spp, double time_limit);

/// Adds the extra subcommands (info, ...) to `app`.
void register_extra_commands(CLI::App& app);

/// Runs whichever extra subcommand was parsed; returns the exit status.
int run_extra_commands(CLI::App& app);

}  // namespace lucent::cli
