/* lucent kernel: the path tracer (docs/rendering-model.md): next-event estimation with multiple
 * importance sampling (power heuristic), Russian roulette, optional clamping. One call computes
 * the radiance of one camera sample; random numbers come from lc_rand8 with the dimension layout
 * of shared/rng.h. */
#ifndef LUCENT_INTEGRATOR_PATH_CL
#define LUCENT_INTEGRATOR_PATH_CL

/* integrator.clamp (docs/rendering-model.md, "Clamping"): a contribution of the path after at
 * least one scattering (next-event estimation, or an emitter or the environment reached by a
 * BSDF-sampled ray) whose largest component exceeds `bound` is scaled to have that largest
 * component; bound 0 is off. Emitters and the environment seen by the camera ray are never
 * clamped. A non-finite contribution stays non-finite (it is counted, not hidden). */
static inline float3 path_clamp(float3 c, float bound) {
#ifdef LC_HAS_CLAMP
  float m = lc_max3(c);
  if (bound > 0.0f && m > bound) c *= bound / m;
#endif
  return c;
}

#ifdef LC_HAS_SPLITTING
/* integrator.dielectric_splits (docs/rendering-model.md, "Integrators"): a branch that waits while
 * the camera path follows the other lobe of a split vertex (LC_MAX_SPLITS at most, types.h) */
typedef struct {
  lc_real3 o, d, prev_p;
  float3 beta;
  lc_uint depth;  /* of the vertex the ray will hit */
  lc_uint splits; /* splits along the branch so far */
} lc_path_branch;
#endif

static inline float3 integrator_path(const lc_scene* s, lc_ray ray, const lc_rng* rng,
                                     lc_uint* rays) {
  __global const lc_params* P = s->params;
  float3 L = (float3)(0.0f), beta = (float3)(1.0f);
  float prev_pdf = 0.0f;
  int prev_delta = 1; /* the camera ray: emitters count fully */
  lc_real3 prev_p = ray.o;
#ifdef LC_HAS_CAUSTICS
  /* integrator.caustics: emitters that a BSDF-sampled ray reaches after a delta lobe, on a path
   * whose lobe at the first hit was a non-delta one (E N (N|S)* S L), are left to the light
   * paths (integrator/caustics.cl). first_n: the lobe sampled at the first hit was non-delta. */
  const int caustics = (P->flags & LC_FLAG_CAUSTICS) != 0;
  int first_n = 0;
#endif
  lc_uint depth = 0;
#ifdef LC_HAS_SPLITTING
  lc_path_branch waiting[LC_MAX_SPLITS];
  int nwaiting = 0;
  lc_uint splits = 0;
  const lc_uint max_splits = min(P->splits, (lc_uint)LC_MAX_SPLITS);
#endif
  /* one pass per branch: the camera path, then (LC_HAS_SPLITTING) each waiting branch */
  for (;;) {
    for (;; ++depth) {
      lc_hit hit;
      ++*rays;
      const int no_mis = (P->flags & LC_FLAG_NO_MIS) != 0;
      if (!scene_intersect(s, ray, INFINITY, &hit)) {
        float pdf_l;
        float3 Le = env_radiance(s, lc_float3_from_real3(ray.d), &pdf_l);
        /* without MIS, light sampling alone covers what it can produce: a direction it never
         * picks (pdf 0: an environment texel without a lattice step) is BSDF sampling's */
        float3 c =
            beta * Le *
            (prev_delta ? 1.0f
                        : (no_mis ? (pdf_l > 0.0f ? 0.0f : 1.0f) : mis_power(prev_pdf, pdf_l)));
        L += depth > 0 ? path_clamp(c, P->clamp) : c;
        break;
      }
      lc_interaction it = interaction_from_hit(s, ray, &hit);
      __global const lc_material* m = &s->materials[it.material];
      int emits = it.front && it.light != LC_INVALID;
#ifdef LC_HAS_CAUSTICS
      if (caustics && first_n && prev_delta) emits = 0;
#endif
      if (emits) {
        float3 Le = lc_load3(m->emission);
        float w = 1.0f;
        if (!prev_delta) {
          /* the light's pdf from prev_p, where light sampling sampled, for this ray's direction
           * (the ray left from an origin off prev_p): its distance along ray.d from prev_p to
           * the emitter's tangent plane at the hit, where light sampling would have put the
           * point (a triangle light's pdf is dist^2 / (cos A), and hit.t, from the origin, made
           * MIS weights that did not sum to 1: a lamp 0.006 wide 0.003 over a floor of +-60
           * lit it 1.4% too brightly in float); 0 behind that plane, where light sampling never
           * picks the light */
          lc_real cos_l = -dot(ray.d, it.ng), h = dot(prev_p - it.p, it.ng);
          lc_real dist_p = h > LC_REAL(0.0) && cos_l > LC_REAL(0.0) ? h / cos_l : LC_REAL(0.0);
          float pdf_l =
              light_pdf(s, it.light, prev_p, lc_float3_from_real3(ray.d), dist_p, (float)cos_l);
          w = no_mis ? (pdf_l > 0.0f ? 0.0f : 1.0f) : mis_power(prev_pdf, pdf_l);
        }
        L += depth > 0 ? path_clamp(beta * Le * w, P->clamp) : beta * Le * w;
      }
      if (depth + 2 > P->max_depth) break;
      lc_uint dim = LC_DIM_BOUNCE + depth * LC_DIMS_PER_BOUNCE;
      /* light point, light selection, lobe; BSDF direction, Russian roulette, the point inside
       * an environment map's texel */
      float8 u = lc_rand8(rng, dim);
      float4 u_light = u.lo, u_bsdf = u.hi;
      lc_bsdf b = bsdf_from_material(s, m, it.uv, it.front);
      lc_frame fr = frame_from(it.ns);
      float3 wo_l = frame_to_local(&fr, lc_float3_from_real3(-ray.d));
      if (wo_l.z <= 0.0f) break;

      /* next-event estimation: the light sampled from the surface point, the shadow ray from the
       * origin o off the surface (the next ray's too); a BSDF that transmits also takes light
       * from behind the surface, with a shadow ray from an origin behind it */
      lc_real3 o = lc_spawn_origin(it.p, it.perr, it.ng);
      lc_uint lobes = bsdf_lobes(&b);
      if (!(lobes & LC_BSDF_DELTA) && P->num_lights > 0) {
        lc_light_sample ls;
        if (light_sample(s, it.p, it.light, u_light.z, u_light.x, u_light.y, u_bsdf.w, &ls) &&
            ls.pdf > 0.0f) {
          int behind = !(dot(ls.wi, it.ng) > LC_REAL(0.0));
          float3 wi_l = frame_to_local(&fr, lc_float3_from_real3(ls.wi));
          /* the side of the geometric surface decides the lobe, and the shading frame must
           * agree (as for sampled directions below: a shading normal leak carries nothing) */
          if ((!behind || (lobes & LC_BSDF_TRANSMISSION)) &&
              (behind ? wi_l.z < 0.0f : wi_l.z > 0.0f)) {
            float pdf_b;
            float3 f = bsdf_eval(&b, wo_l, wi_l, &pdf_b);
            /* the light was sampled from it.p; the shadow ray leaves from o, or from behind the
             * surface, as BSDF-sampled rays do. Those never reach a light whose emitting side
             * faces away from their origin (a lamp nearly touching the surface, the origin
             * inside it or behind its plane): the light sample is then the only strategy, with
             * weight 1 (MIS gave it its usual share, and a sphere lamp 3e-5 over a floor lit
             * the point under it 57% too dark in float, a square lamp not at all) */
            lc_real3 so = behind ? lc_spawn_origin(it.p, it.perr, -it.ng) : o;
            if (lc_max3(f) > 0.0f && shadow_visible_sample(s, so, it.p, &ls, rays)) {
              float w = (ls.delta || no_mis || !light_seen_from(s, &ls, so))
                            ? 1.0f
                            : mis_power(ls.pdf, pdf_b);
              L += path_clamp(beta * f * ls.L * (fabs(wi_l.z) * w / ls.pdf), P->clamp);
            }
          }
        }
      }

      /* continue the path */
      lc_bsdf_sample bs;
#ifdef LC_HAS_SPLITTING
      /* a BSDF that chooses between delta lobes (smooth glass: reflection with probability F,
       * refraction with 1 - F), at one of the first max_splits such vertices of the branch: both
       * lobes, each weighted by its probability; the refraction's branch waits */
      int split = 0;
      if (splits < max_splits && (lobes & LC_BSDF_DELTA)) {
        lc_bsdf_sample bt;
        if (bsdf_sample(&b, wo_l, 0.0f, u_bsdf.x, u_bsdf.y, &bs) && bs.prob < 1.0f &&
            bsdf_sample(&b, wo_l, LC_ONE_MINUS_EPSILON, u_bsdf.x, u_bsdf.y, &bt) &&
            bt.prob < 1.0f) {
          split = 1;
          ++splits;
          bs.weight *= bs.prob;
          lc_real3 wt = frame_to_world_dir(&fr, bt.wi);
          int t_transmit = bt.wi.z < 0.0f;
          lc_real t_side = dot(wt, it.ng);
          float3 t_beta = beta * bt.weight * bt.prob;
          /* the leak test and the origin of the continuation below; one helper for both measured
           * 2% slower on course (the hot path's ray then computed before its throughput tests) */
          if ((t_transmit ? t_side < LC_REAL(0.0) : t_side > LC_REAL(0.0)) &&
              lc_max3(t_beta) > 0.0f) {
            lc_path_branch* w = &waiting[nwaiting++];
            w->o = t_transmit ? lc_spawn_origin(it.p, it.perr, -it.ng) : o;
            w->d = wt;
            w->prev_p = it.p;
            w->beta = t_beta;
            w->depth = depth + 1;
            w->splits = splits;
          }
        }
      }
      if (!split && !bsdf_sample(&b, wo_l, u_light.w, u_bsdf.x, u_bsdf.y, &bs)) break;
#else
      if (!bsdf_sample(&b, wo_l, u_light.w, u_bsdf.x, u_bsdf.y, &bs)) break;
#endif
      lc_real3 wi = frame_to_world_dir(&fr, bs.wi);
      int transmit = bs.wi.z < 0.0f;
      lc_real side = dot(wi, it.ng);
      if (transmit ? side >= LC_REAL(0.0) : side <= LC_REAL(0.0)) break; /* shading normal leak */
      beta *= bs.weight;
      if (!(lc_max3(beta) > 0.0f)) break;
#ifdef LC_HAS_CAUSTICS
      if (depth == 0) first_n = !bs.delta;
#endif
      prev_delta = bs.delta;
      prev_pdf = bs.pdf;
      ray.o = transmit ? lc_spawn_origin(it.p, it.perr, -it.ng) : o;
      prev_p = it.p; /* light pdfs for MIS are evaluated from where light sampling sampled */
      ray.d = wi;
      /* Russian roulette: survive with probability max(beta) while it is below 1, so the
       * throughput after the division never exceeds 1 (a cap such as min(0.95, max(beta)) makes
       * beta grow like (albedo / 0.95)^n on albedos above 0.95: unbiased, infinite variance) */
      float q = lc_max3(beta);
      if (depth + 2 > P->rr_depth && q < 1.0f) {
        if (u_bsdf.z >= q) break;
        beta /= q;
      }
    }
#ifdef LC_HAS_SPLITTING
    /* the next waiting branch: it left a delta vertex (no MIS on what it hits) */
    if (nwaiting == 0) break;
    lc_path_branch* w = &waiting[--nwaiting];
    ray.o = w->o;
    ray.d = w->d;
    prev_p = w->prev_p;
    beta = w->beta;
    depth = w->depth;
    splits = w->splits;
    prev_delta = 1;
    prev_pdf = 0.0f;
#else
    break;
#endif
  }
  return L;
}

#endif
