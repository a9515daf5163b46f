/* lucent kernel: small vector helpers and robust ray offsets. */
#ifndef LUCENT_UTIL_MATH_CL
#define LUCENT_UTIL_MATH_CL

#define LC_PI 3.14159265358979323846f
#define LC_INV_PI 0.31830988618379067154f
#define LC_INF INFINITY

typedef struct {
  float3 o;
  float3 d; /* unit length */
} lc_ray;

static inline float3 lc_load3(const __global float* p) { return (float3)(p[0], p[1], p[2]); }
static inline float3 lc_load3c(__constant float* p) { return (float3)(p[0], p[1], p[2]); }
static inline float lc_max3(float3 v) { return fmax(v.x, fmax(v.y, v.z)); }
static inline float lc_luminance(float3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
static inline int lc_isfinite3(float3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

/* Orthonormal basis around unit n (Duff et al. 2017, "Building an Orthonormal Basis, Revisited"). */
static inline void lc_onb(float3 n, float3* t, float3* b) {
  float s = copysign(1.0f, n.z);
  float a = -1.0f / (s + n.z);
  float c = n.x * n.y * a;
  *t = (float3)(1.0f + s * n.x * n.x * a, s * c, -s * n.x);
  *b = (float3)(c, s + n.y * n.y * a, -n.y);
}

/*
 * Offset a spawned ray's origin off the surface along the geometric normal n (pointing to the
 * side the ray leaves from), by a few ulps of the hit position rather than a fixed epsilon
 * (Wächter and Binder, "A Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing
 * Gems ch. 6). The offset scales with |p|, so tiny and huge scenes both work.
 */
static inline float3 lc_offset_ray_origin(float3 p, float3 n) {
  const float origin = 1.0f / 32.0f;
  const float float_scale = 1.0f / 65536.0f;
  const float int_scale = 256.0f;
  int3 of_i = convert_int3(int_scale * n);
  float3 p_i = (float3)(as_float(as_int(p.x) + ((p.x < 0.0f) ? -of_i.x : of_i.x)),
                        as_float(as_int(p.y) + ((p.y < 0.0f) ? -of_i.y : of_i.y)),
                        as_float(as_int(p.z) + ((p.z < 0.0f) ? -of_i.z : of_i.z)));
  return (float3)(fabs(p.x) < origin ? p.x + float_scale * n.x : p_i.x,
                  fabs(p.y) < origin ? p.y + float_scale * n.y : p_i.y,
                  fabs(p.z) < origin ? p.z + float_scale * n.z : p_i.z);
}

/* Origin for a ray leaving a surface point p with position error bound perr (per component),
 * towards the side n points to: first past the error bound along n (pbrt-v4's OffsetRayOrigin),
 * then a few ulps more (Wächter-Binder). */
static inline float3 lc_spawn_origin(float3 p, float3 perr, float3 n) {
  float d = dot(fabs(n), perr);
  return lc_offset_ray_origin(p + d * n, n);
}

#endif
