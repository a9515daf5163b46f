#pragma once
// The limits of a scene's settings, written once: the scene loader, the scene builder, the
// command line (--width, --spp, ...) and `lucent converge` settings all check against these.
#include <cstdint>

namespace lucent::limits {

/// Film width and height: 1 .. kMaxImageSize pixels.
inline constexpr int kMaxImageSize = 16384;
/// Samples per pixel: 1 .. kMaxSpp.
inline constexpr int kMaxSpp = 1 << 24;
/// A time limit (render --time, --checkpoint-every, converge's time ladder): at most kMaxSeconds
/// (about 116 days).
inline constexpr double kMaxSeconds = 1e7;
/// Integrator max_depth and rr_depth: 1 .. kMaxDepth path segments.
inline constexpr int kMaxDepth = 100000;
/// integrator.dielectric_splits: 0 .. kMaxDielectricSplits smooth-glass vertices per camera path
/// at which both lobes are followed (up to 2^N branches per camera sample; the kernel's stack of
/// waiting branches, LC_MAX_SPLITS, holds N).
inline constexpr int kMaxDielectricSplits = 4;  // = LC_MAX_SPLITS (kernels/shared/types.h)
/// Pixel filter radius: (0, kMaxFilterRadius] pixels.
inline constexpr double kMaxFilterRadius = 8;
/// Geometry range: every coordinate of the camera position, the shapes (a sphere's centre plus or
/// minus its radius, a mesh's vertices after its transform) and the point lights is at most
/// kMaxCoordinate in magnitude. The kernel's triangle test multiplies three coordinate differences
/// (edge functions times a distance), which overflows float near 7e12: beyond this range geometry
/// vanished from the image instead of failing. Scales/StabilityScale renders its scene with
/// coordinates up to 5e11 (at 5e12 it still passed when tried, at 5e13 it failed).
inline constexpr double kMaxCoordinate = 1e12;
/// Random seed: 0 .. kMaxSeed (32 bits).
inline constexpr std::uint32_t kMaxSeed = 0xffffffffu;
/// A texture's uv scale (Material::albedo_uv_scale): each component kMinUvScale .. kMaxUvScale
/// in magnitude (negative mirrors the image about uv 0, docs/rendering-model.md "Textures"). 0
/// would read one point of the image everywhere, and a sphere's float uvs (mapped in the kernel)
/// lose the texels beyond about 1e6 repetitions.
inline constexpr double kMinUvScale = 1e-6;
inline constexpr double kMaxUvScale = 1e6;
/// A texture's uv offset (Material::albedo_uv_offset): each component at most kMaxUvOffset in
/// magnitude.
inline constexpr double kMaxUvOffset = 1e6;

}  // namespace lucent::limits
