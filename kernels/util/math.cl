/* lucent kernel: small vector helpers and robust ray offsets. */
#ifndef LUCENT_UTIL_MATH_CL
#define LUCENT_UTIL_MATH_CL

/*
 * LC_POCL_NOINLINE: on PoCL's CPU device (LC_DEVICE_POCL_CPU, which the host adds to that device's
 * build options: render_detail::device_defines) a function called once per sample is kept out of
 * line, so that PoCL's work-group passes, which run at the first launch over the kernel with
 * everything inlined into it, see a small kernel: the cold build of the Cornell box took 1.00 s
 * with the integrator inlined, 0.80 s without, at the same speed (BENCHMARKS.md, "Kernel
 * specialisation"). Other devices keep their compilers' choice: Intel's CPU runtime (2026.2)
 * renders 2.2x slower with the integrator out of line, builds 3x slower, and miscompiles an
 * out-of-line function that returns a float3 (each work-item read its neighbours' components),
 * BENCHMARKS.md, "Intel's CPU OpenCL runtime".
 */
#ifdef LC_DEVICE_POCL_CPU
#define LC_POCL_NOINLINE __attribute__((noinline))
#else
#define LC_POCL_NOINLINE inline
#endif

/*
 * Precision of ray and geometry arithmetic (--precision): lc_real is float by default and double
 * when the build defines LC_DOUBLE (devices with fp64). Buffers always hold float; values loaded
 * from them are widened with lc_load3r / lc_real3_from_float3. LC_REAL(x) writes a literal in the
 * chosen precision.
 */
#ifdef LC_DOUBLE
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
typedef double lc_real;
typedef double2 lc_real2;
typedef double3 lc_real3;
typedef double4 lc_real4;
#define LC_REAL(x) (x)
#define lc_real3_from_float3(v) convert_double3(v)
#define lc_float3_from_real3(v) convert_float3(v)
/* unit roundoff (half an ulp of 1) and machine epsilon of lc_real */
#define LC_REAL_U (1.0 / 9007199254740992.0)
#define LC_REAL_EPSILON DBL_EPSILON
/* lc_real3's bits as signed integers, and the sign bit */
typedef long3 lc_real3_bits;
#define lc_as_real3_bits(v) as_long3(v)
#define lc_real3_from_bits(v) as_double3(v)
#define LC_REAL_SIGN_BIT ((long)0x8000000000000000UL)
#else
typedef float lc_real;
typedef float2 lc_real2;
typedef float3 lc_real3;
typedef float4 lc_real4;
#define LC_REAL(x) (x##f)
#define lc_real3_from_float3(v) (v)
#define lc_float3_from_real3(v) (v)
#define LC_REAL_U (1.0f / 16777216.0f)
#define LC_REAL_EPSILON FLT_EPSILON
typedef int3 lc_real3_bits;
#define lc_as_real3_bits(v) as_int3(v)
#define lc_real3_from_bits(v) as_float3(v)
#define LC_REAL_SIGN_BIT ((int)0x80000000u)
#endif

#define LC_PI 3.14159265358979323846f
#define LC_ONE_MINUS_EPSILON 0x1.fffffep-1f /* the largest float below 1 */
#define LC_INV_PI 0.31830988618379067154f
#define LC_INF INFINITY

typedef struct {
  lc_real3 o;
  lc_real3 d; /* unit length */
} lc_ray;

static inline float3 lc_load3(const __global float* p) { return (float3)(p[0], p[1], p[2]); }
static inline lc_real3 lc_load3r(const __global float* p) {
  return (lc_real3)((lc_real)p[0], (lc_real)p[1], (lc_real)p[2]);
}
/* The same from a 16-byte aligned float[3] whose struct puts an ordinary float after it (one
 * vector load where lc_load3 takes four instructions): the fourth lane is loaded and computed
 * with, so an integer field there, a subnormal as a float, would slow every operation on the
 * triple (shared/types.h, lc_triangle). */
static inline float3 lc_load3a(const __global float* p) { return (*(const __global float4*)p).xyz; }
#ifdef LC_DOUBLE
static inline lc_real3 lc_load3ra(const __global float* p) {
  return convert_double3((*(const __global float4*)p).xyz);
}
#else
#define lc_load3ra lc_load3a
#endif
static inline float3 lc_load3c(__constant float* p) { return (float3)(p[0], p[1], p[2]); }
static inline float lc_luminance(float3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
static inline int lc_isfinite3(float3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

/*
 * Helpers needed both in float (shading) and in lc_real (geometry), written once: LC_MATH_HELPERS
 * defines them for one scalar type T with the given name suffix. Under LC_DOUBLE the lc_real set
 * is a second, double copy; otherwise its names are those of the float set.
 *  - lc_max3: the largest component.
 *  - lc_unit_circler (double): (cos 2 pi u, sin 2 pi u) for u in [0, 1) with sinpi/cospi, which
 *    reduce their argument exactly (a multiple of pi); the float one, lc_unit_circle, is below.
 *  - lc_onb: orthonormal basis t, b around unit n (Duff et al. 2017, "Building an Orthonormal
 *    Basis, Revisited").
 */
#define LC_MATH_HELPERS(SUFFIX, T, T2, T3)                                    \
  static inline T lc_max3##SUFFIX(T3 v) { return fmax(v.x, fmax(v.y, v.z)); } \
  static inline void lc_onb##SUFFIX(T3 n, T3* t, T3* b) {                     \
    T s = copysign((T)1, n.z);                                                \
    T a = (T)-1 / (s + n.z);                                                  \
    T c = n.x * n.y * a;                                                      \
    *t = (T3)((T)1 + s * n.x * n.x * a, s * c, -s * n.x);                     \
    *b = (T3)(c, s + n.y * n.y * a, -n.y);                                    \
  }

LC_MATH_HELPERS(, float, float2, float3)
#ifdef LC_DOUBLE
LC_MATH_HELPERS(r, double, double2, double3)
static inline double2 lc_unit_circler(double u) {
  return (double2)(cospi(2.0 * u), sinpi(2.0 * u));
}
#else
#define lc_max3r lc_max3
#define lc_unit_circler lc_unit_circle
#define lc_onbr lc_onb
#endif
#undef LC_MATH_HELPERS

/*
 * (cos 2 pi u, sin 2 pi u) for u in [0, 1) (BSDF, light and filter sampling): the quarter turn
 * k = rint(4 u) and the rest r = u - k / 4 in [-1/8, 1/8] are exact (u is a float), and the sine
 * and cosine of x = 2 pi r in [-pi/4, pi/4] are their Taylor polynomials of degree 9 and 8
 * (truncated below 3e-8). Within 1e-7 of the exact point, within 2e-7 of the unit circle, exact at
 * quarter turns (tests/test_kernel_bsdf.cpp, UnitCircleIsAccurate). It replaces PoCL's sinpi and
 * cospi: 78 fewer instructions per path on the Cornell box (callgrind).
 */
static inline float2 lc_unit_circle(float u) {
  /* rint(4 u) by adding and subtracting 1.5 * 2^23, where floats are integers: round to nearest
   * even, as rint, in two instructions where PoCL's rint took ~27 */
  float k = (4.0f * u + 12582912.0f) - 12582912.0f;
  float x = (u - 0.25f * k) * 6.28318530717958647692f;
  float x2 = x * x;
  float sn =
      x * (1.0f + x2 * (-1.0f / 6.0f +
                        x2 * (1.0f / 120.0f + x2 * (-1.0f / 5040.0f + x2 * (1.0f / 362880.0f)))));
  float cs =
      1.0f + x2 * (-0.5f + x2 * (1.0f / 24.0f + x2 * (-1.0f / 720.0f + x2 * (1.0f / 40320.0f))));
  /* the quarter turn's rotation without branches (a random u mispredicted both): lanes swapped by
   * a vector select on odd k, signs flipped by their bits */
  uint q = (uint)(int)k;
  float2 v = select((float2)(cs, sn), (float2)(-sn, cs), (int2)(-(int)(q & 1u)));
  return as_float2(as_uint2(v) ^ (uint2)((q & 2u) << 30));
}

/* nextafter(o, copysign(INFINITY, n)) per component for finite o, o where n is 0, as integer
 * steps of o's bits: +1 where o and n have the same sign, -1 where they differ, the smallest
 * subnormal with n's sign from a zero. A dozen vector instructions where PoCL's vector nextafter
 * took ~37 (tests/test_stability_spawn.cpp, SpawnStep). */
static inline lc_real3 lc_step_along(lc_real3 o, lc_real3 n) {
  lc_real3_bits ob = lc_as_real3_bits(o), nb = lc_as_real3_bits(n);
  /* (ob ^ nb) < 0: the signs differ (-1, true), so the step is -1; otherwise +1 */
  lc_real3_bits r = ob + (((ob ^ nb) < 0) | 1);
  r = select(r, (nb & LC_REAL_SIGN_BIT) | 1, o == (lc_real3)(LC_REAL(0.0)));
  return lc_real3_from_bits(select(r, ob, n == (lc_real3)(LC_REAL(0.0))));
}

/*
 * Origin for a ray leaving a surface point p towards the side the geometric normal n points to,
 * given perr, a bound on the absolute error of p per component. No fixed epsilon: the offset
 * scales with the primitive's coordinates, from 1e-8 to 1e8 (tests/test_stability_spawn.cpp).
 *  - d: past the error bound along n (pbrt-v4's OffsetRayOrigin), plus twice the bound's largest
 *    component: the next ray's intersection with the same primitive errs by a few ulps of the
 *    primitive's coordinates, which perr's component along n alone need not cover (a floor at
 *    y = 0 has perr.y = 0 however large it is);
 *  - then one ulp further per component along the sign of n (pbrt-v4; nothing where n is 0), so
 *    that rounding p + d n cannot undo it: lc_step_along (three scalar nextafter calls behind
 *    branches on n's signs took 90 more instructions per path).
 * Everything is in lc_real: with --precision double, perr holds double's error bounds (a few ulps
 * of double, set by interaction_from_hit) and the ulp is double's, so the offset is ~5e8 times
 * smaller than in float.
 * This replaces Wächter and Binder's integer offset (Ray Tracing Gems ch. 6), which added an
 * absolute 1/65536 to coordinates below 1/32 (up to 14% of the rays entering spheres of radius
 * < 1e-2 near the origin missed their far side; a scene of size 1e-4 rendered 4% too bright) and
 * 256 ulps elsewhere (2 units at 1e5: a scene of size 100 translated to 1e5 rendered 2.4% too
 * bright). Found by tests/test_stability_spawn.cpp and tests/test_stability_scene.cpp.
 */
static inline lc_real3 lc_spawn_origin(lc_real3 p, lc_real3 perr, lc_real3 n) {
  lc_real d = dot(fabs(n), perr) + LC_REAL(2.0) * lc_max3r(perr);
  return lc_step_along(p + d * n, n);
}

/* A cosine-distributed direction about +z (BSDFs, and lights emitting light paths). */
static inline float3 sample_cosine_hemisphere(float u1, float u2) {
  return (float3)(sqrt(u1) * lc_unit_circle(u2), sqrt(fmax(0.0f, 1.0f - u1)));
}

#endif
