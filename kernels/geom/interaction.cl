/* lucent kernel: surface interaction at the closest hit: position, normals, texture coordinates. */
#ifndef LUCENT_GEOM_INTERACTION_CL
#define LUCENT_GEOM_INTERACTION_CL

/* Position, its error bound and the geometric normal are lc_real (double with --precision
 * double); the shading normal and texture coordinates, which only feed BSDFs and textures, are
 * float in both precisions. */
typedef struct {
  lc_real3 p;     /* hit position, recomputed from the primitive (not o + t d)            */
  lc_real3 perr;  /* bound on the absolute error of p, per component                      */
  lc_real3 ng;    /* geometric normal, facing the incoming ray                            */
  float3 ns;      /* shading normal, on the same side as ng                               */
  float2 uv;      /* texture coordinates                                                  */
  lc_uint material;
  lc_uint light;  /* light index if the primitive emits, else LC_INVALID                  */
  int front;      /* 1 when the ray hit the outside (the side the stored normal points to) */
} lc_interaction;

static inline lc_interaction interaction_from_hit(const lc_scene* s, lc_ray ray, const lc_hit* hit) {
  lc_interaction it;
  it.p = it.perr = it.ng = (lc_real3)(LC_REAL(0.0));
  it.ns = (float3)(0.0f);
  it.uv = (float2)(0.0f);
  it.material = 0;
  it.light = LC_INVALID;
#ifdef LC_HAS_SPHERES
  if (hit->prim & LC_PRIM_SPHERE_BIT) {
    __global const lc_sphere* sp = &s->spheres[hit->prim & ~LC_PRIM_SPHERE_BIT];
    lc_real3 c = lc_load3r(sp->center);
    lc_real3 p = ray.o + hit->t * ray.d;
    lc_real3 n = normalize(p - c);
    it.p = c + sp->radius * n; /* reproject onto the surface */
    /* a few ulps of |c| + r: the representation limit (in lc_real) of this sphere's surface */
    it.perr = (fabs(c) + sp->radius) * (LC_REAL(8.0) * LC_REAL_U);
    it.ng = n;
    float3 nf = lc_float3_from_real3(n);
    it.ns = nf;
    /* equirectangular uv: u along longitude around +y, v from the south to the north pole */
    it.uv = (float2)(0.5f + atan2(nf.z, nf.x) * (0.5f * LC_INV_PI),
                     0.5f + asin(clamp(nf.y, -1.0f, 1.0f)) * LC_INV_PI);
    it.material = sp->material;
    it.light = sp->light;
  } else
#endif
  {
#ifdef LC_HAS_TRIANGLES
    __global const lc_triangle* tri = &s->triangles[hit->prim];
    lc_real3 v0 = lc_load3r(tri->v0), v1 = lc_load3r(tri->v1), v2 = lc_load3r(tri->v2);
    lc_real b1 = hit->b1, b2 = hit->b2, b0 = LC_REAL(1.0) - b1 - b2;
    it.p = b0 * v0 + b1 * v1 + b2 * v2;
    /* gamma(7) bound of the barycentric interpolation (pbrt-v4, section 6.8), lc_real's gamma */
    it.perr = (fabs(b0 * v0) + fabs(b1 * v1) + fabs(b2 * v2)) *
              (LC_REAL(7.0) * LC_REAL_U * LC_REAL(1.0001));
    lc_real3 ng = normalize(cross(v1 - v0, v2 - v0));
    it.ng = ng;
    float3 ngf = lc_float3_from_real3(ng);
    it.ns = ngf;
    float fb0 = (float)b0, fb1 = (float)b1, fb2 = (float)b2;
    it.uv = (float2)(fb1, fb2);
#if defined(LC_HAS_SMOOTH_NORMALS) || defined(LC_HAS_UVS)
    if (tri->flags & (LC_TRI_HAS_NORMALS | LC_TRI_HAS_UVS)) {
      __global const lc_triangle_attr* a = &s->tri_attrs[hit->prim];
#ifdef LC_HAS_SMOOTH_NORMALS
      if (tri->flags & LC_TRI_HAS_NORMALS) {
        float3 ns = fb0 * lc_load3(a->n) + fb1 * lc_load3(a->n + 3) + fb2 * lc_load3(a->n + 6);
        float len = length(ns);
        if (len > 0.0f) {
          ns /= len;
          /* interpolated normals stay on the geometric side */
          it.ns = dot(ns, ngf) < 0.0f ? -ns : ns;
        }
      }
#endif
#ifdef LC_HAS_UVS
      if (tri->flags & LC_TRI_HAS_UVS)
        it.uv = (float2)(fb0 * a->uv[0] + fb1 * a->uv[2] + fb2 * a->uv[4],
                         fb0 * a->uv[1] + fb1 * a->uv[3] + fb2 * a->uv[5]);
#endif
    }
#endif
    it.material = tri->material;
    it.light = tri->light;
#endif
  }
  it.front = dot(ray.d, it.ng) < LC_REAL(0.0);
  if (!it.front) {
    it.ng = -it.ng;
    it.ns = -it.ns;
  }
  /* an interpolated normal facing away from the viewer: fall back to the geometric one */
  if (dot(lc_float3_from_real3(ray.d), it.ns) >= 0.0f) it.ns = lc_float3_from_real3(it.ng);
  return it;
}

#endif
