#!/usr/bin/env bash
# First command of README: install what is missing, build in Release what the default render
# needs (the library and the CLI: not the tests, not the benchmark), render the default scene to
# out/default.png. The build tree is the one scripts/test.sh uses, which then adds the rest.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build $(scripts/generator.sh build) -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(scripts/cpus.sh)" --target lucent_cli
mkdir -p out
build/lucent render scenes/default.json -o out/default.png
echo "setup: the default scene is in out/default.png"
