#!/usr/bin/env bash
# Second command of README (and what CI runs): install what is missing, build, run every test.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)"
# a private PoCL kernel cache, so runs do not depend on what a user's cache holds
export POCL_CACHE_DIR="$PWD/build/pocl-cache"
export LUCENT_CACHE_DIR="$PWD/build/lucent-cache"
cd build
ctest --output-on-failure -j"$(nproc)" --timeout 600
