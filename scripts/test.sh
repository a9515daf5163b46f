#!/usr/bin/env bash
# Second command of README (and what CI runs): install what is missing, build, run every test.
# With LUCENT_SANITIZE=1 (CI sets it) the suite then runs again on an AddressSanitizer +
# UndefinedBehaviorSanitizer build in build-asan/ (built by clang when it is installed), and, when
# clang with libFuzzer is installed (scripts/install-deps.sh --with-fuzz), each fuzz target runs
# for LUCENT_FUZZ_SECONDS (default 5; 0 skips it) in build-fuzz/ (scripts/fuzz.sh).
#
# Sized for a slow, shared machine (docs/testing.md): as many builds and tests at a time as there
# are CPUs this process may really use (scripts/cpus.sh: the affinity mask and the cgroup CPU
# quota, not the host's CPU count), and one PoCL worker thread per test process, so that N test
# processes keep N CPUs busy instead of starting N x (host CPUs) threads.
set -euo pipefail
cd "$(dirname "$0")/.."
# CI (LUCENT_SANITIZE=1) checks the formatting too (the CTest entry format.clang_format)
if [[ "${LUCENT_SANITIZE:-0}" == "1" ]]; then scripts/install-deps.sh --with-format; else
  scripts/install-deps.sh
fi
jobs="${LUCENT_TEST_JOBS:-$(scripts/cpus.sh)}"
echo "test: $jobs job(s) at a time (scripts/cpus.sh; LUCENT_TEST_JOBS overrides)"

# private caches, so runs do not depend on what a user's caches hold; the sanitizer stage uses
# the same ones (same kernels, same device: every program is already built)
export POCL_CACHE_DIR="$PWD/build/pocl-cache"
export LUCENT_CACHE_DIR="$PWD/build/lucent-cache"
# one PoCL worker per test process: ctest runs $jobs of them at a time
export POCL_MAX_PTHREAD_COUNT="${POCL_MAX_PTHREAD_COUNT:-1}"

# every stage reports its wall and CPU time (CPU time depends little on what else the machine runs)
timed() {
  local label="$1" TIMEFORMAT
  shift
  TIMEFORMAT="test: $label: %0R s wall, %0U + %0S s CPU"
  time "$@"
}

# CI builds and tests the Python module once, in the sanitizer stage (ASan on the bindings, and
# the installed module's import: python.installed_module); the release build skips it there. The
# module and its tests are a quarter of each build and about 100 s of test CPU per stage
# (docs/testing.md). Without LUCENT_SANITIZE the release build has it (README's second command).
release_python=ON
if [[ "${LUCENT_SANITIZE:-0}" == "1" ]]; then release_python=OFF; fi
cmake -S . -B build $(scripts/generator.sh build) -DCMAKE_BUILD_TYPE=Release \
  -DLUCENT_BUILD_PYTHON="$release_python"
timed "release build" cmake --build build -j"$jobs"
timed "release tests" ctest --test-dir build --output-on-failure -j"$jobs"

if [[ "${LUCENT_SANITIZE:-0}" == "1" ]]; then
  # clang when it is installed with its sanitizer runtimes (Debian: clang, libclang-rt-14-dev;
  # install-deps.sh --with-fuzz), else the default compiler. clang compiles this build in 0.55
  # of GCC's CPU time and its -O2 code runs the tests in 1.2 times GCC's -O1 code's time (GCC's
  # -O2 would cost more to compile than it saves): about 140 s of CPU less in all (docs/testing.md).
  asan_compiler=()
  asan_name="$(c++ --version | head -1)"
  asan_opt="-O1"
  probe="$(mktemp -d)"
  echo 'int main() { return 0; }' >"$probe/p.cpp"
  if command -v clang++ >/dev/null && command -v clang >/dev/null &&
    clang++ -fsanitize=address,undefined -shared-libasan "$probe/p.cpp" -o "$probe/p" \
      >/dev/null 2>&1; then
    asan_compiler=(-DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++)
    asan_name="$(clang++ --version | head -1)"
    asan_opt="-O2"
  fi
  rm -rf "$probe"
  echo "test: sanitizer build (ASan + UBSan; $asan_name, $asan_opt)"
  # -g1: file:line in every report at a fraction of -g's compile time
  cmake -S . -B build-asan $(scripts/generator.sh build-asan) "${asan_compiler[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DLUCENT_SANITIZE=ON -DLUCENT_BUILD_BENCH=OFF \
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=$asan_opt -g1 -DNDEBUG" \
    "-DCMAKE_C_FLAGS_RELWITHDEBINFO=$asan_opt -g1 -DNDEBUG"
  timed "sanitizer build" cmake --build build-asan -j"$jobs"
  # PoCL and the ICD loader keep allocations until exit: leak checking reports theirs, not ours.
  # use_sigaltstack=0: PoCL's LLVM gives the thread that first compiles its own alternate signal
  # stack (malloc'd) when the one there is smaller than it wants, and ASan's teardown of that
  # thread then unmaps the malloc'd block and aborts ("failed to deallocate", EINVAL). Seen with
  # Session.SessionsCreatedConcurrentlyFromThreads where SIGSTKSZ is 13504 (AVX-512 machines).
  ASAN_OPTIONS=detect_leaks=0:use_sigaltstack=0 UBSAN_OPTIONS=print_stacktrace=1 \
    timed "sanitizer tests" ctest --test-dir build-asan --output-on-failure -j"$jobs"
fi

if [[ "${LUCENT_SANITIZE:-0}" == "1" && "${LUCENT_FUZZ_SECONDS:-5}" != "0" ]]; then
  echo "test: fuzz smoke run (${LUCENT_FUZZ_SECONDS:-5} s per target)"
  export FUZZ_JOBS="$jobs"
  # a smoke run: the targets build, start and take their seeds; -O0 halves to thirds their build
  # (third_party.cpp 18 -> 7 s) at the cost of executions, which 10 s do not need
  FUZZ_FLAGS="${FUZZ_FLAGS:--O0 -g1}" \
    timed "fuzz smoke run" scripts/fuzz.sh --if-available "${LUCENT_FUZZ_SECONDS:-5}"
fi
