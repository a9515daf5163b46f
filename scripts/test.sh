#!/usr/bin/env bash
# Second command of README (and what CI runs): install what is missing, build, run every test.
# With LUCENT_SANITIZE=1 (CI sets it) the suite then runs again on an AddressSanitizer +
# UndefinedBehaviorSanitizer build in build-asan/, and, when clang with libFuzzer is installed
# (scripts/install-deps.sh --with-fuzz), each fuzz target runs for LUCENT_FUZZ_SECONDS (default
# 30; 0 skips it) in build-fuzz/ (scripts/fuzz.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
jobs="$(nproc)"

# private caches, so runs do not depend on what a user's caches hold
export POCL_CACHE_DIR="$PWD/build/pocl-cache"
export LUCENT_CACHE_DIR="$PWD/build/lucent-cache"

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$jobs"
(cd build && ctest --output-on-failure -j"$jobs" --timeout 600)

if [[ "${LUCENT_SANITIZE:-0}" == "1" ]]; then
  echo "test: sanitizer build (ASan + UBSan)"
  cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLUCENT_SANITIZE=ON -DLUCENT_BUILD_BENCH=OFF
  cmake --build build-asan -j"$jobs"
  # PoCL and the ICD loader keep allocations until exit: leak checking reports theirs, not ours
  (cd build-asan && ASAN_OPTIONS=detect_leaks=0 UBSAN_OPTIONS=print_stacktrace=1 \
     ctest --output-on-failure -j"$jobs" --timeout 900)
fi

if [[ "${LUCENT_SANITIZE:-0}" == "1" && "${LUCENT_FUZZ_SECONDS:-30}" != "0" ]]; then
  echo "test: fuzz smoke run (${LUCENT_FUZZ_SECONDS:-30} s per target)"
  FUZZ_JOBS="$jobs" scripts/fuzz.sh --if-available "${LUCENT_FUZZ_SECONDS:-30}"
fi
