// lucent::render(): a one-shot render session (src/render/session.cpp).
#include "lucent/render.hpp"
#include "lucent/session.hpp"

namespace lucent {

RenderResult render(const Scene& scene, const RenderOptions& options) {
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
