#pragma once
// Which integrator reads which of the integrator's knobs: an option or a converge setting that
// the render's integrator would ignore is refused rather than taken without a word.
#include "lucent/scene.hpp"

namespace lucent::render_detail {

enum class IntegratorKnob { MaxDepth, RrDepth, Clamp, Caustics, Splits, Mis };

/// nullptr when integrator `type` reads `knob`, else why not ("only the path integrator has it").
/// The path integrator reads them all; whitted reads max_depth; direct and the AOVs none.
const char* knob_ignored(IntegratorType type, IntegratorKnob knob);

}  // namespace lucent::render_detail
