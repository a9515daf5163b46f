#include "render/integrator_knobs.hpp"

namespace lucent::render_detail {

const char* knob_ignored(IntegratorType type, IntegratorKnob knob) {
  if (type == IntegratorType::Path) return nullptr;
  if (knob == IntegratorKnob::MaxDepth)
    return type == IntegratorType::Whitted ? nullptr
                                           : "only the path and whitted integrators have it";
  return "only the path integrator has it";
}

}  // namespace lucent::render_detail
