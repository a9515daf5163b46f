#!/usr/bin/env bash
# Prints the CMake generator option for the build directory DIR: -GNinja when Ninja is installed
# and DIR is new (Ninja compiles a target's files while the libraries it links are still being
# built, and starts faster: the release build in 186 s of wall time against Make's 211 s on the
# 2-vCPU machine, docs/testing.md); nothing when DIR is already configured (a build directory
# keeps its generator), when CMAKE_GENERATOR chooses one, or without Ninja (Make).
#
#   cmake -S . -B build $(scripts/generator.sh build) ...
dir="${1:?usage: scripts/generator.sh DIR}"
if [[ -z "${CMAKE_GENERATOR:-}" && ! -f "$dir/CMakeCache.txt" ]] && command -v ninja >/dev/null; then
  echo "-GNinja"
fi
