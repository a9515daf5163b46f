#pragma once
// lucent: a physically based OpenCL path tracer. Umbrella header: every public header (compare,
// converge and reference were missing).
#include "lucent/accumulation.hpp"
#include "lucent/compare.hpp"
#include "lucent/converge.hpp"
#include "lucent/device.hpp"
#include "lucent/error.hpp"
#include "lucent/image.hpp"
#include "lucent/limits.hpp"
#include "lucent/parts.hpp"
#include "lucent/reference.hpp"
#include "lucent/render.hpp"
#include "lucent/scene.hpp"
#include "lucent/scene_builder.hpp"
#include "lucent/session.hpp"
#include "lucent/types.hpp"
#include "lucent/version.hpp"
#include "lucent/warnings.hpp"
