#pragma once
// The scalar reference integrator: an independent, double-precision, CPU implementation of
// docs/rendering-model.md, written for clarity rather than speed. It shares only the scene
// description and the counter-based random numbers (kernels/shared/rng.h) with the OpenCL kernel;
// its intersection code, BSDFs and light sampling are its own, so that comparing the two (see
// lucent/compare.hpp) catches bugs in either.
#include <atomic>
#include <cstdint>

#include "lucent/render.hpp"
#include "lucent/scene.hpp"

namespace lucent {

struct ReferenceOptions {
  int spp = 0;      ///< samples per pixel; 0: the scene's integrator.spp
  int threads = 0;  ///< worker threads (rows are shared out); 0: the hardware's concurrency
  const std::atomic<bool>* cancel = nullptr;  ///< set to stop after the rows under way
  /// Its warnings (a scene without lights, degenerate triangles skipped, ...); null: the calling
  /// thread's ScopedWarningSink (lucent/warnings.hpp), else "lucent: warning: ..." on stderr.
  WarningSink on_warning;
};

/// Renders `scene` with the reference integrator. The result has the same meaning as the
/// kernel's (lucent::render): per-pixel mean, sample variance (of one sample, n - 1 in the
/// denominator) and count of finite samples; `device` reads "reference (N threads)". Cancelled,
/// its spp is the samples launched per pixel on average, rounded down.
/// Throws lucent::Error for scenes it cannot render (e.g. an out-of-range material index).
RenderResult render_reference(const Scene& scene, const ReferenceOptions& options = {});

namespace reference {

/// Exact unpolarized Fresnel reflectance of a dielectric interface for light arriving at cosine
/// `cos_i` (>= 0) to the normal, `eta` = n_transmitted / n_incident. 1 under total internal
/// reflection.
double fresnel_dielectric(double cos_i, double eta);

}  // namespace reference

}  // namespace lucent
