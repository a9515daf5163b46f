#pragma once
// The binned SAH builder's arithmetic (bvh_build.cpp, sah_builder.cpp): four floats in one SIMD
// register where SSE2 is there (V4), a box of them (Box) and a primitive's bounds carrying its
// reference (PrimRef). Host only.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "shared/types.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace lucent::bvh::detail {

// Four floats, one SIMD register where SSE2 is there (lane 3 is unused by the math below).
#if defined(__SSE2__)
struct V4 {
  __m128 v;
  static V4 load(const float* p) { return {_mm_load_ps(p)}; }
  static V4 splat(float x) { return {_mm_set1_ps(x)}; }
  static V4 xyz(float x, float y, float z) { return {_mm_setr_ps(x, y, z, 0.0f)}; }
  void store(float* p) const { _mm_store_ps(p, v); }
  V4 xyz_only() const {  // lane 3 set to 0
    return {_mm_and_ps(v, _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0)))};
  }
  // index of the bin per lane: trunc(clamp(this, 0, top)); NaN goes to 0
  void bins(float top, int* out) const {
    __m128 f = _mm_min_ps(_mm_max_ps(v, _mm_setzero_ps()), _mm_set1_ps(top));
    _mm_store_si128(reinterpret_cast<__m128i*>(out), _mm_cvttps_epi32(f));
  }
};
inline V4 operator+(V4 a, V4 b) { return {_mm_add_ps(a.v, b.v)}; }
inline V4 operator-(V4 a, V4 b) { return {_mm_sub_ps(a.v, b.v)}; }
inline V4 operator*(V4 a, V4 b) { return {_mm_mul_ps(a.v, b.v)}; }
inline V4 vmin(V4 a, V4 b) { return {_mm_min_ps(a.v, b.v)}; }
inline V4 vmax(V4 a, V4 b) { return {_mm_max_ps(a.v, b.v)}; }
#else
struct V4 {
  float f[4];
  static V4 load(const float* p) { return {{p[0], p[1], p[2], p[3]}}; }
  static V4 splat(float x) { return {{x, x, x, x}}; }
  static V4 xyz(float x, float y, float z) { return {{x, y, z, 0.0f}}; }
  void store(float* p) const {
    for (int a = 0; a < 4; ++a) p[a] = f[a];
  }
  V4 xyz_only() const { return {{f[0], f[1], f[2], 0.0f}}; }
  void bins(float top, int* out) const {
    for (int a = 0; a < 4; ++a) {
      float x = f[a] > 0.0f ? f[a] : 0.0f;
      out[a] = static_cast<int>(x < top ? x : top);
    }
  }
};
inline V4 operator+(V4 a, V4 b) {
  return {{a.f[0] + b.f[0], a.f[1] + b.f[1], a.f[2] + b.f[2], a.f[3] + b.f[3]}};
}
inline V4 operator-(V4 a, V4 b) {
  return {{a.f[0] - b.f[0], a.f[1] - b.f[1], a.f[2] - b.f[2], a.f[3] - b.f[3]}};
}
inline V4 operator*(V4 a, V4 b) {
  return {{a.f[0] * b.f[0], a.f[1] * b.f[1], a.f[2] * b.f[2], a.f[3] * b.f[3]}};
}
inline V4 vmin(V4 a, V4 b) {
  V4 r;
  for (int i = 0; i < 4; ++i) r.f[i] = b.f[i] < a.f[i] ? b.f[i] : a.f[i];
  return r;
}
inline V4 vmax(V4 a, V4 b) {
  V4 r;
  for (int i = 0; i < 4; ++i) r.f[i] = b.f[i] > a.f[i] ? b.f[i] : a.f[i];
  return r;
}
#endif

struct Box {
  V4 lo = V4::splat(INFINITY), hi = V4::splat(-INFINITY);
  void grow(V4 l, V4 h) {
    lo = vmin(lo, l);
    hi = vmax(hi, h);
  }
  void grow(const Box& b) { grow(b.lo, b.hi); }
  void grow_point(V4 p) { grow(p, p); }
  void get(float* l, float* h) const {
    alignas(16) float a[4], b[4];
    lo.store(a);
    hi.store(b);
    for (int k = 0; k < 3; ++k) {
      l[k] = a[k];
      h[k] = b[k];
    }
  }
  float area() const {
    alignas(16) float d[4];
    vmax(hi - lo, V4::splat(0.0f)).store(d);
    return 2 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0]);
  }
  float max_extent() const {
    alignas(16) float d[4];
    (hi - lo).store(d);
    return std::max(d[0], std::max(d[1], d[2]));  // NaN-free when the box is
  }
};

// One primitive: its bounds and its reference (32 bytes). The reference rides in lane 3 of lo.
struct PrimRef {
  V4 lo, hi;
  lc_uint id() const {
    alignas(16) float f[4];
    lo.store(f);
    lc_uint i;
    std::memcpy(&i, &f[3], sizeof i);
    return i;
  }
  V4 centroid2() const { return lo.xyz_only() + hi; }  // twice the centroid, lane 3 = 0
};
static_assert(sizeof(PrimRef) == 32, "PrimRef should stay 32 bytes");

}  // namespace lucent::bvh::detail
