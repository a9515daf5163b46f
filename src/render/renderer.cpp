// lucent::render(): a one-shot render session (src/render/session.cpp).
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "lucent/error.hpp"
#include "lucent/render.hpp"
#include "lucent/session.hpp"
#include "scene/validate.hpp"

namespace lucent {

std::string target_shortfall(const RenderResult& r) {
  if (!(r.target_error > 0) || r.cancelled) return "";
  char line[400];
  // a time limit stopped it in the pilot: no plan was made, and the estimates read a partial
  // pilot (the halves' difference none at all where only one half had samples): the render
  // ended without a word, exit 0, looking like a finished one
  if (r.pilot_incomplete) {
    std::snprintf(line, sizeof line,
                  "the time limit stopped the render in its pilot, at %llu of its %llu spp: no "
                  "plan was made and the error is not estimated (target %.3g): raise --time",
                  static_cast<unsigned long long>(r.spp),
                  static_cast<unsigned long long>(r.planned_spp), r.target_error);
    return line;
  }
  // 1.5 E, widened by twice the relative sd of the halves' estimate on a small film (a mean of
  // 3 npix terms of one degree of freedom each: sqrt(2 / (3 npix)))
  const double npix = std::max(1.0, double(r.mean.width) * double(r.mean.height));
  const double limit = 1.5 * r.target_error * (1 + 2 * std::sqrt(2 / (3 * npix)));
  if (!(r.halves_relmse > limit)) return "";
  // %.3g: a tiny target made %.1f print hundreds of digits, and the line was cut short
  if (r.plan_incomplete)  // the time limit, not the plan (its advice named only the plan's causes)
    std::snprintf(line, sizeof line,
                  "the halves' difference estimates relMSE %.3g, %.3g times the target %.3g: the "
                  "time limit stopped the render at %llu of the %llu spp its plan asked for: "
                  "raise --time",
                  r.halves_relmse, r.halves_relmse / r.target_error, r.target_error,
                  static_cast<unsigned long long>(r.spp),
                  static_cast<unsigned long long>(r.planned_spp));
  else
    std::snprintf(
        line, sizeof line,
        "the halves' difference estimates relMSE %.3g, %.3g times the target %.3g (rare "
        "bright samples that no pilot foresees, or the --spp cap): lower "
        "--target-error or raise --spp (the path integrator's clamp trades such samples for "
        "bias)",
        r.halves_relmse, r.halves_relmse / r.target_error, r.target_error);
  return line;
}

RenderResult render(const Scene& scene, const RenderOptions& options) {
  // (a negative count or a NaN target would otherwise fall back to a default without a word)
  if (options.spp < 0)
    throw Error("render: RenderOptions::spp must be >= 0 (0: the scene's), got " +
                std::to_string(options.spp));
  if (options.min_spp < 0)
    throw Error("render: RenderOptions::min_spp must be >= 0 (0: the default), got " +
                std::to_string(options.min_spp));
  if (!(options.target_error >= 0) || !std::isfinite(options.target_error))
    throw Error("render: RenderOptions::target_error must be a finite number >= 0 (0: off), got " +
                scene_detail::format_number(options.target_error));
  // the pilot of an adaptive render: a uniform render has none (it was ignored without a word,
  // as lucent render refuses --min-spp without --target-error)
  if (options.min_spp > 0 && options.target_error == 0)
    throw Error(
        "render: RenderOptions::min_spp is the pilot of an adaptive render: it needs a "
        "target_error");
  SessionOptions so;
  so.device = options.device;
  so.kernel_dir = options.kernel_dir;
  so.cache_dir = options.cache_dir;
  so.precision = options.precision;
  so.fast_math = options.fast_math;
  so.specialize = options.specialize;
  so.pass_seconds = options.pass_seconds;
  so.on_warning = options.on_warning;
  Renderer renderer(so);
  renderer.set_cancel_flag(options.cancel);
  renderer.set_scene(scene);
  if (options.target_error > 0) {
    AdaptiveOptions ao;
    ao.target_error = options.target_error;
    if (options.min_spp > 0) ao.min_spp = static_cast<std::uint32_t>(options.min_spp);
    if (options.spp > 0) ao.max_spp = static_cast<std::uint32_t>(options.spp);
    ao.max_seconds = options.time_limit;
    renderer.render_adaptive(ao, options.on_progress);
    return renderer.result();
  }
  std::uint64_t spp = options.spp > 0 ? static_cast<std::uint64_t>(options.spp)
                                      : (options.time_limit > 0 ? 0 : scene.integrator.spp);
  renderer.render(spp, options.time_limit, options.on_progress);
  return renderer.result();
}

}  // namespace lucent
