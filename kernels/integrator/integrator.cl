/* lucent kernel: the integrator dispatch. Each integrator of shared/registry.h
 * (LC_INTEGRATOR_TYPES) has its file integrator/<file>.cl defining
 *   float3 integrator_<file>(const lc_scene* s, lc_ray ray, const lc_rng* rng, lc_uint* rays)
 * the radiance of one camera sample (rays counts the rays it traces); the AOVs (LC_AOV_TYPES) share
 * integrator_aov (integrator/aov.cl). A branch is compiled only when its feature define is set. */
#ifndef LUCENT_INTEGRATOR_INTEGRATOR_CL
#define LUCENT_INTEGRATOR_INTEGRATOR_CL

#include "integrator/common.cl"
/* integrator/<file>.cl for every integrator */
/* clang-format off */
#include "generated/integrators.cl"
#include "integrator/aov.cl"
/* clang-format on */
#ifdef LC_HAS_CAUSTICS
#include "integrator/caustics.cl"
#endif

#define LC_INTEGRATOR_CALL(ID, Name, value, name, feature, file) \
  if (LC_ENABLED(feature) && integrator == LC_INTEGRATOR_##ID)   \
    return integrator_##file(s, ray, rng, rays);
/* The radiance of one camera sample with the integrator of lc_params.integrator (out of line on
 * PoCL's CPU device: LC_POCL_NOINLINE, util/math.cl). */
static LC_POCL_NOINLINE float3 integrate(const lc_scene* s, lc_ray ray, const lc_rng* rng,
                                         lc_uint* rays) {
  lc_uint integrator = s->params->integrator;
  LC_INTEGRATOR_TYPES(LC_INTEGRATOR_CALL)
#ifdef LC_HAS_INTEGRATOR_AOV
  if (integrator >= LC_INTEGRATOR_FIRST_AOV) return integrator_aov(s, ray, rng, rays);
#endif
  return (float3)(0.0f);
}
#undef LC_INTEGRATOR_CALL

#endif
