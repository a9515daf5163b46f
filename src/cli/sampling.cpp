// The sampling options of the command line: the sampler, clamping, adaptive sampling.
#include <optional>
#include <string>

#include "cli/commands.hpp"
#include "lucent/error.hpp"
#include "lucent/limits.hpp"
#include "lucent/types.hpp"

namespace lucent::cli {

void add_sampling_options(CLI::App* cmd, SamplingArgs& a, bool adaptive) {
  cmd->add_option("--sampler", a.sampler,
                  "Random numbers: " + type_names<SamplerType>() +
                      " (overrides integrator.sampler; default sobol)")
      ->check(non_empty());
  cmd->add_option("--clamp", a.clamp,
                  "Largest contribution of a path vertex after a scattering (overrides "
                  "integrator.clamp; 0: off; biased when it binds)")
      ->check(non_negative_real());
  CLI::Option* caustics = cmd->add_flag_callback(
      "--caustics", [&a] { a.caustics = 1; },
      "Caustic paths by light tracing (integrator.caustics; path integrator)");
  cmd->add_flag_callback(
         "--no-caustics", [&a] { a.caustics = 0; }, "Caustic paths by the camera path alone")
      ->excludes(caustics);  // (both were accepted, the last one winning)
  cmd->add_option("--dielectric-splits", a.splits,
                  "Smooth-glass vertices per camera path at which both reflection and refraction "
                  "are followed (overrides integrator.dielectric_splits; default 2; 0: off)")
      ->check(CLI::Range(0, limits::kMaxDielectricSplits));
  if (!adaptive) return;
  cmd->add_option("--target-error", a.target_error,
                  "Adaptive sampling: render until the image's estimated relMSE is at most this, "
                  "with --spp as the most samples per pixel and --time as a time limit")
      ->check(positive_real());
  cmd->add_option("--min-spp", a.min_spp,
                  "Adaptive sampling (with --target-error): samples per pixel of the pilot, "
                  "everywhere (default 64)")
      ->check(CLI::Range(4, limits::kMaxSpp));
}

void check_knob(const Scene& scene, bool given, render_detail::IntegratorKnob knob,
                const char* option) {
  if (!given) return;
  if (const char* why = render_detail::knob_ignored(scene.integrator.type, knob))
    throw Error(std::string(option) + ": " + why + ", and this render's is " +
                type_name(scene.integrator.type));
}

void apply_sampling_options(const SamplingArgs& a, Scene& scene) {
  if (!a.sampler.empty()) {
    std::optional<SamplerType> t = find_type<SamplerType>(a.sampler);
    if (!t)
      throw Error("--sampler " + a.sampler + ": unknown sampler (expected " +
                  type_names<SamplerType>() + ")");
    scene.integrator.sampler = *t;
  }
  // what only the path integrator reads: refused for another, rather than ignored without a word
  using render_detail::IntegratorKnob;
  check_knob(scene, a.clamp >= 0, IntegratorKnob::Clamp, "--clamp");
  // (--no-caustics too: it changes nothing for them either)
  check_knob(scene, a.caustics >= 0, IntegratorKnob::Caustics,
             a.caustics == 1 ? "--caustics" : "--no-caustics");
  check_knob(scene, a.splits >= 0, IntegratorKnob::Splits, "--dielectric-splits");
  if (a.clamp >= 0) scene.integrator.clamp = a.clamp;
  if (a.caustics >= 0) scene.integrator.caustics = a.caustics == 1;
  if (a.splits >= 0) scene.integrator.dielectric_splits = a.splits;
}

AdaptiveOptions adaptive_options(const SamplingArgs& a, int max_spp, double time_limit) {
  AdaptiveOptions o;
  o.target_error = a.target_error;
  if (a.min_spp > 0) o.min_spp = static_cast<std::uint32_t>(a.min_spp);
  if (max_spp > 0) o.max_spp = static_cast<std::uint32_t>(max_spp);
  // the pilot's two halves hold (min_spp + 1) / 2 samples each: an odd --min-spp rounds up
  const std::uint32_t pilot = 2 * ((o.min_spp + 1) / 2);
  if (o.max_spp < pilot)
    // (without --spp the cap is the default's: "--spp 16384" named an option not given)
    throw Error(
        (max_spp > 0
             ? "--spp " + std::to_string(o.max_spp)
             : "the default cap of " + std::to_string(o.max_spp) + " samples per pixel (--spp)") +
        " is below the adaptive pilot (--min-spp " + std::to_string(o.min_spp) +
        (pilot != o.min_spp ? ", rounded up to the even " + std::to_string(pilot) : "") + ")");
  o.max_seconds = time_limit;
  return o;
}

}  // namespace lucent::cli
