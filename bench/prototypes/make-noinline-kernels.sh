#!/usr/bin/env bash
# Writes a copy of kernels/ in which each stage of the path tracer is a function of its own, so
# that perf and callgrind attribute the megakernel's time to stages (BENCHMARKS.md, "Where the
# time goes"). PoCL inlines everything else into the work-group function; bvh_trace is inlined
# into two noinline wrappers, so closest-hit and shadow rays are told apart.
#
#   bench/prototypes/make-noinline-kernels.sh OUT_DIR      # then LUCENT_KERNEL_DIR=OUT_DIR/kernels
#
# The noinline calls cost the kernel about 11% more instructions and 17% more CPU time (Cornell
# box, measured at f227b8a). The patterns match the kernel sources of 28 Nov 2026 (f5cbc08); the
# script stops with a message when one of them no longer matches. integrate() itself is a
# function of its own in every build (LC_POCL_NOINLINE); stage_profile.py looks inside it.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
out=${1:?usage: make-noinline-kernels.sh OUT_DIR}
mkdir -p "$out"
rm -rf "$out/kernels"
cp -r "$root/kernels" "$out/kernels"
k=$out/kernels
patch_one() {  # file, pattern (a function definition's start), replacement
  grep -q "^$2" "$k/$1" || { echo "make-noinline-kernels: '$2' not found in kernels/$1" >&2; exit 1; }
  sed -i "s/^$2/$3/" "$k/$1"
}
NI='__attribute__((noinline)) static'
patch_one bvh/traverse.cl 'static inline int bvh_trace(' 'static inline __attribute__((always_inline)) int bvh_trace('
patch_one bvh/traverse.cl 'static inline int scene_intersect(' "$NI int scene_intersect("
patch_one bvh/traverse.cl 'static inline int scene_occluded(' "$NI int scene_occluded("
patch_one geom/interaction.cl 'static inline lc_interaction interaction_from_hit(' "$NI lc_interaction interaction_from_hit("
patch_one bsdf/bsdf.cl 'static inline lc_bsdf bsdf_from_material(' "$NI lc_bsdf bsdf_from_material("
patch_one bsdf/bsdf.cl 'static inline float3 bsdf_eval(' "$NI float3 bsdf_eval("
patch_one bsdf/bsdf.cl 'static inline int bsdf_sample(' "$NI int bsdf_sample("
patch_one light/light.cl 'static inline float3 env_radiance(' "$NI float3 env_radiance("
patch_one light/light.cl 'static inline float light_pdf(' "$NI float light_pdf("
patch_one light/light.cl 'static inline int light_sample(' "$NI int light_sample("
patch_one camera/camera.cl 'static inline lc_ray camera_generate_ray(' "$NI lc_ray camera_generate_ray("
patch_one film/filter.cl 'static inline float2 filter_sample(' "$NI float2 filter_sample("
patch_one sampler/sampler.cl 'static inline float8 lc_rand8(' "$NI float8 lc_rand8("
patch_one sampler/sampler.cl 'static inline float2 lc_rand2(' "$NI float2 lc_rand2("
echo "make-noinline-kernels: wrote $k (use LUCENT_KERNEL_DIR=$k)"
