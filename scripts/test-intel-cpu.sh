#!/usr/bin/env bash
# The test suite (or one command) on Intel's CPU OpenCL runtime, a second OpenCL implementation for
# the same CPU: it compiles the kernels with Intel's own compiler, so it finds what PoCL lets pass
# (BENCHMARKS.md, "Intel's CPU OpenCL runtime"). Installs nothing: the runtime is not a Debian
# package. Unpack PyPI's wheels once (the ICD file they carry names a path that does not exist):
#
#   pip download intel-opencl-rt tbb intel-cmplr-lib-rt --no-deps -d /tmp/iocl
#   cd /tmp/iocl && for w in *.whl; do unzip -q -o "$w" -d x; done
#   mkdir -p lib && cp -a x/*/data/lib/* lib/
#
# then, from a build directory made by scripts/test.sh or cmake:
#
#   scripts/test-intel-cpu.sh /tmp/iocl/lib [BUILD_DIR] [-- COMMAND ...]
#
# Without a command it runs ctest in BUILD_DIR (default build). The Intel device is selected by
# its whole name (LUCENT_DEVICE), beside PoCL's (whose name contains it), both ICDs visible. Skips
# with a message (exit 0) when DIR has no libintelocl.so or it lists no device.
set -euo pipefail
cd "$(dirname "$0")/.."
lib="${1:-}"
if [[ -z "$lib" || ! -f "$lib/libintelocl.so" ]]; then
  echo "test-intel-cpu: no libintelocl.so in '${lib}': skipped (see the comment at the top)"
  exit 0
fi
lib="$(cd "$lib" && pwd)"
shift
build=build
if [[ $# -gt 0 && "$1" != "--" ]]; then
  build="$1"
  shift
fi
[[ $# -gt 0 && "$1" == "--" ]] && shift
# absolute (an absolute BUILD_DIR gave the caches "$PWD//abs/build/..." under the checkout)
build="$(cd "$build" && pwd)"

vendors="$(mktemp -d)"
trap 'rm -rf "$vendors"' EXIT
echo "$lib/libintelocl.so" >"$vendors/intel-cpu.icd"
cp /etc/OpenCL/vendors/*.icd "$vendors/" 2>/dev/null || true
export OCL_ICD_VENDORS="$vendors"
export LD_LIBRARY_PATH="$lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"

name="$("$build/lucent" devices | sed -n 's/.*Intel(R) OpenCL *\(.*[^ ]\) *CPU .*/\1/p' | head -1)"
if [[ -z "$name" ]]; then
  "$build/lucent" devices || true
  echo "test-intel-cpu: Intel's CPU runtime lists no device: skipped"
  exit 0
fi
export LUCENT_DEVICE="$name"
# the binaries of one runtime are not the other's: a cache of its own
export LUCENT_CACHE_DIR="$build/lucent-cache-intel"
export POCL_CACHE_DIR="$build/pocl-cache"
echo "test-intel-cpu: LUCENT_DEVICE='$name'"
# not exec: the EXIT trap removes $vendors after the command (exec left it in TMPDIR every run)
status=0
if [[ $# -gt 0 ]]; then
  "$@" || status=$?
else
  ctest --test-dir "$build" --output-on-failure -j"${LUCENT_TEST_JOBS:-$(scripts/cpus.sh)}" ||
    status=$?
fi
exit "$status"
