#!/usr/bin/env bash
# First command of README: install what is missing, build in Release, render the default scene
# to out/default.png.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)"
mkdir -p out
build/lucent render scenes/default.json -o out/default.png
echo "setup: the default scene is in out/default.png"
