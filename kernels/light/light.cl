/* lucent kernel: light sampling for next-event estimation and the matching pdfs for MIS.
 * Lights are chosen in proportion to power (lc_light.pdf_select, cumulative in light_cdf).
 * Spheres are sampled by the cone they subtend, triangles by area, constant environments
 * uniformly over the sphere, environment maps by texel luminance times sin(theta). */
#ifndef LUCENT_LIGHT_LIGHT_CL
#define LUCENT_LIGHT_LIGHT_CL

typedef struct {
  lc_real3 wi;  /* unit direction towards the light                          */
  lc_real dist; /* distance to the sampled point (INFINITY for environments) */
  float3 L;    /* radiance arriving (I / r^2 for point lights)              */
  float pdf;   /* solid-angle pdf including the selection probability;
                  for point lights the selection probability                */
  int delta;   /* point light: no MIS                                        */
} lc_light_sample;

/* Index i with cdf[i-1] <= u < cdf[i] over n entries (cdf[n-1] = 1). */
static inline lc_uint lc_cdf_search(__global const float* cdf, lc_uint n, float u) {
  lc_uint lo = 0, hi = n - 1;
  while (lo < hi) {
    lc_uint mid = (lo + hi) >> 1;
    if (cdf[mid] <= u)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

static inline float3 sample_uniform_sphere(float u1, float u2) {
  float z = 1.0f - 2.0f * u1;
  float r = sqrt(fmax(0.0f, 1.0f - z * z));
  return (float3)(r * lc_unit_circle(u2), z);
}

/* ---- environment map: equirectangular, nearest texel (docs/rendering-model.md) ---- */
#ifdef LC_HAS_ENV_MAP
static inline float3 env_map_radiance(const lc_scene* s, __global const lc_light* L, float3 d, lc_uint* texel) {
  __global const lc_texture* tex = &s->textures[L->texture];
  float u = 0.5f + atan2(d.x, -d.z) * (0.5f * LC_INV_PI);
  float v = acos(clamp(d.y, -1.0f, 1.0f)) * LC_INV_PI;
  int x = clamp((int)(u * (float)tex->width), 0, (int)tex->width - 1);
  int y = clamp((int)(v * (float)tex->height), 0, (int)tex->height - 1);
  *texel = (lc_uint)y * tex->width + (lc_uint)x;
  return lc_load3(L->intensity) * s->texels[tex->offset + *texel].xyz;
}

/* Solid-angle pdf (without selection) of sampling direction d. */
static inline float env_map_pdf(const lc_scene* s, __global const lc_light* L, float3 d) {
  lc_uint texel;
  env_map_radiance(s, L, d, &texel);
  __global const lc_texture* tex = &s->textures[L->texture];
  __global const float* cdf = s->light_cdf + L->prim;
  float p = cdf[texel + 1] - cdf[texel];
  float sin_t = sqrt(d.x * d.x + d.z * d.z); /* not sqrt(1 - y^2): precise near the poles */
  if (sin_t <= 0.0f) return 0.0f;
  return p * (float)(tex->width * tex->height) / (2.0f * LC_PI * LC_PI * sin_t);
}
#endif

/* Radiance of a ray escaping the scene in direction d, and the pdf (with selection) with which
 * light sampling would have produced d. */
static inline float3 env_radiance(const lc_scene* s, float3 d, float* pdf) {
  __global const lc_params* P = s->params;
  *pdf = 0.0f;
  if (P->env_light < 0) return (float3)(0.0f);
  __global const lc_light* L = &s->lights[P->env_light];
#ifdef LC_HAS_ENV_MAP
  if (L->type == LC_LIGHT_ENV_MAP) {
    lc_uint texel;
    *pdf = L->pdf_select * env_map_pdf(s, L, d);
    return env_map_radiance(s, L, d, &texel);
  }
#endif
#ifdef LC_HAS_ENV
  *pdf = L->pdf_select * (0.25f * LC_INV_PI);
  return lc_load3(L->intensity);
#else
  return (float3)(0.0f);
#endif
}

/* Solid-angle pdf (with selection) that light sampling from p picks the point seen along wi on
 * emitter `light` at distance dist with light-side cosine cos_l (> 0). */
static inline float light_pdf_area(const lc_scene* s, lc_uint light, lc_real3 p, lc_real dist,
                                   float cos_l) {
  __global const lc_light* L = &s->lights[light];
#ifdef LC_HAS_SPHERE_LIGHTS
  if (L->type == LC_LIGHT_SPHERE) {
    __global const lc_sphere* sp = &s->spheres[L->prim];
    lc_real3 d = lc_load3r(sp->center) - p;
    lc_real r = sp->radius;
    lc_real dc2 = dot(d, d), r2 = r * r;
    if (dc2 <= r2) return 0.0f;
    lc_real sin2 = r2 / dc2;
    lc_real cosmax = sqrt(fmax(LC_REAL(0.0), LC_REAL(1.0) - sin2));
    lc_real one_minus = sin2 / (LC_REAL(1.0) + cosmax);
    return L->pdf_select / (2.0f * LC_PI * one_minus);
  }
#endif
#ifdef LC_HAS_TRIANGLE_LIGHTS
  /* triangle, area sampling */
  if (L->type == LC_LIGHT_TRIANGLE && cos_l > 0.0f) return L->pdf_select * dist * dist / (cos_l * L->area);
#endif
  return 0.0f;
}

static inline int light_sample(const lc_scene* s, lc_real3 p, float us, float u1, float u2,
                               lc_light_sample* ls) {
  __global const lc_params* P = s->params;
  if (P->num_lights == 0) return 0;
  lc_uint li = lc_cdf_search(s->light_cdf, P->num_lights, us);
  __global const lc_light* L = &s->lights[li];
  ls->delta = 0;
#ifdef LC_HAS_POINT_LIGHTS
  if (L->type == LC_LIGHT_POINT) {
    lc_real3 to = lc_load3r(L->position) - p;
    lc_real d2 = dot(to, to);
    if (!(d2 > LC_REAL(0.0))) return 0;
    ls->dist = sqrt(d2);
    ls->wi = to / ls->dist;
    ls->L = lc_load3(L->intensity) / (float)d2;
    ls->pdf = L->pdf_select;
    ls->delta = 1;
    return 1;
  }
#endif
#ifdef LC_HAS_SPHERE_LIGHTS
  if (L->type == LC_LIGHT_SPHERE) {
    __global const lc_sphere* sp = &s->spheres[L->prim];
    lc_real3 c = lc_load3r(sp->center);
    lc_real r = sp->radius;
    lc_real3 d = c - p;
    lc_real dc2 = dot(d, d);
    if (dc2 <= r * r) return 0; /* inside: the emitting side faces away */
    lc_real dc = sqrt(dc2);
    lc_real sin2max = r * r / dc2;
    lc_real cosmax = sqrt(fmax(LC_REAL(0.0), LC_REAL(1.0) - sin2max));
    lc_real one_minus_cosmax = sin2max / (LC_REAL(1.0) + cosmax);
    /* cone sampling (pbrt-v4 Sphere::Sample), precise for tiny cones */
    lc_real one_minus_cos_t = one_minus_cosmax * u1;
    lc_real cos_t = LC_REAL(1.0) - one_minus_cos_t;
    lc_real sin2t = one_minus_cos_t * (LC_REAL(2.0) - one_minus_cos_t);
    /* angle alpha at the sphere centre between -d and the sampled point */
    lc_real cos_a = sin2t / sqrt(sin2max) +
                    cos_t * sqrt(fmax(LC_REAL(0.0), LC_REAL(1.0) - sin2t / sin2max));
    cos_a = clamp(cos_a, LC_REAL(-1.0), LC_REAL(1.0));
    lc_real sin_a = sqrt(fmax(LC_REAL(0.0), LC_REAL(1.0) - cos_a * cos_a));
    /* phi's sine and cosine in lc_real: in float |n| is 1 only to a float ulp, which puts q
     * ~1e-7 r off the sphere (covered by shadow_visible's float margin, not by its double one) */
    lc_real2 cs = sin_a * lc_unit_circler((lc_real)u2);
    lc_real3 wc = -d / dc; /* from the centre towards p */
    lc_real3 t, b;
    lc_onbr(wc, &t, &b);
    lc_real3 n = cs.x * t + cs.y * b + cos_a * wc;
    lc_real3 q = c + r * n;
    lc_real3 to = q - p;
    lc_real dist = length(to);
    if (!(dist > LC_REAL(0.0))) return 0;
    ls->wi = to / dist;
    ls->dist = dist;
    ls->L = lc_load3(L->intensity);
    ls->pdf = L->pdf_select / (2.0f * LC_PI * one_minus_cosmax);
    return 1;
  }
#endif
#ifdef LC_HAS_TRIANGLE_LIGHTS
  if (L->type == LC_LIGHT_TRIANGLE) {
    __global const lc_triangle* tri = &s->triangles[L->prim];
    lc_real3 v0 = lc_load3r(tri->v0), v1 = lc_load3r(tri->v1), v2 = lc_load3r(tri->v2);
    /* barycentrics in lc_real: in float their sum is off 1 by an ulp, which puts q ~1e-7 |v| off
     * the light's plane (covered by shadow_visible's float margin, not by its double one) */
    lc_real su = sqrt((lc_real)u1);
    lc_real b0 = LC_REAL(1.0) - su, b1 = u2 * su;
    lc_real3 q = b0 * v0 + b1 * v1 + (LC_REAL(1.0) - b0 - b1) * v2;
    lc_real3 nl = normalize(cross(v1 - v0, v2 - v0));
    lc_real3 to = q - p;
    lc_real d2 = dot(to, to);
    lc_real dist = sqrt(d2);
    if (!(dist > LC_REAL(0.0))) return 0;
    ls->wi = to / dist;
    lc_real cos_l = -dot(ls->wi, nl);
    if (cos_l <= LC_REAL(0.0)) return 0; /* one-sided emitter seen from behind */
    ls->dist = dist;
    ls->L = lc_load3(L->intensity);
    ls->pdf = L->pdf_select * d2 / (cos_l * L->area);
    return 1;
  }
#endif
#ifdef LC_HAS_ENV_MAP
  if (L->type == LC_LIGHT_ENV_MAP) {
    __global const lc_texture* tex = &s->textures[L->texture];
    lc_uint n = tex->width * tex->height;
    __global const float* cdf = s->light_cdf + L->prim; /* n + 1 entries, cdf[0] = 0 */
    lc_uint k = lc_cdf_search(cdf + 1, n, u1);
    float lo = cdf[k], hi = cdf[k + 1];
    float fx = hi > lo ? (u1 - lo) / (hi - lo) : 0.5f;
    lc_uint x = k % tex->width, y = k / tex->width;
    float u = ((float)x + clamp(fx, 0.0f, 0.99999f)) / (float)tex->width;
    float v = ((float)y + u2) / (float)tex->height;
    /* theta = pi v, phi = 2 pi (u - 1/2) */
    float st = sinpi(v);
    if (!(st > 0.0f)) return 0;
    float2 cp = lc_unit_circle(u - 0.5f);
    ls->wi = lc_real3_from_float3((float3)(st * cp.y, cospi(v), -st * cp.x));
    ls->dist = INFINITY;
    ls->L = lc_load3(L->intensity) * s->texels[tex->offset + k].xyz;
    ls->pdf = L->pdf_select * (hi - lo) * (float)n / (2.0f * LC_PI * LC_PI * st);
    return ls->pdf > 0.0f;
  }
#endif
#ifdef LC_HAS_ENV
  if (L->type == LC_LIGHT_ENV) {
    ls->wi = lc_real3_from_float3(sample_uniform_sphere(u1, u2));
    ls->dist = INFINITY;
    ls->L = lc_load3(L->intensity);
    ls->pdf = L->pdf_select * (0.25f * LC_INV_PI);
    return 1;
  }
#endif
  return 0;
}

#endif
