#!/usr/bin/env bash
# Packs what scripts/gpu-run.sh needs on a lent GPU machine that has NVIDIA's driver but none of
# lucent's Debian build dependencies (the device tool's machines: Ubuntu 24.04, no network):
#   .gpu/bin      build/lucent and build/tests/lucent_tests (built here, Release)
#   .gpu/lib      the shared libraries they need that such a machine lacks (ocl-icd's libOpenCL,
#                 stb, tinyexr, tinyobjloader), from this Debian machine
#   .gpu/shared.tgz   ../shared/assets (the tests' and benchmarks' meshes)
#   .whl/site.tar.xz  with --mitsuba: Mitsuba 3.9.1 and Dr.Jit 1.5.0 for CPython 3.12, pruned to
#                 the cuda_ad_rgb variant and the plugins bench_mitsuba.py uses (21 MB instead of
#                 67 MB of wheels; the device tool carries at most 64 MiB)
# .gpu/ and .whl/ are listed in .git/info/exclude; name them in the device tool's `carry`.
#
#   scripts/gpu-pack.sh [--mitsuba]        then, on the GPU machine: bash scripts/gpu-run.sh STAGES
set -euo pipefail
cd "$(dirname "$0")/.."
# (git's path: in a worktree .git is a file, and '>>.git/info/exclude' stopped the script here)
exclude=$(git rev-parse --git-path info/exclude)
mkdir -p "$(dirname "$exclude")"
grep -qx '/.gpu/' "$exclude" 2>/dev/null || printf '/.gpu/\n/.whl/\n' >>"$exclude"
cmake --build build -j"$(nproc)" --target lucent_cli lucent_tests
rm -rf .gpu && mkdir -p .gpu/bin .gpu/lib
cp build/lucent build/tests/lucent_tests .gpu/bin/ && strip .gpu/bin/*
for l in libOpenCL.so.1 libstb.so.0 libtinyexr.so.1d libtinyobjloader.so.2rc10; do
  cp -L "/lib/x86_64-linux-gnu/$l" .gpu/lib/
done
[[ -d ../shared/assets ]] && tar czf .gpu/shared.tgz -C .. shared/assets
if [[ ${1:-} == --mitsuba ]]; then
  tmp=$(mktemp -d) && trap 'rm -rf "$tmp"' EXIT
  python3 -m pip download -q --no-deps --only-binary=:all: --python-version 3.12 --implementation cp \
    --platform manylinux_2_28_x86_64 --platform manylinux_2_27_x86_64 -d "$tmp" \
    mitsuba==3.9.1 drjit==1.5.0
  (cd "$tmp" && for w in *.whl; do unzip -q -o "$w"; done &&
    cd mitsuba && rm -rf include data/sunsky data/srgb.coeff ./*_mono*.so ./*_spectral*.so llvm_ad_rgb*.so &&
    (cd plugins && rm -f volpathmis.so volpath.so ellipsoids.so ellipsoidsmesh.so bsplinecurve.so \
      linearcurve.so timed_sunsky.so sunsky.so sdfgrid.so) && rm -rf ../drjit/include)
  mkdir -p .whl && tar cJf .whl/site.tar.xz -C "$tmp" mitsuba drjit
fi
du -sh .gpu .whl 2>/dev/null || true
