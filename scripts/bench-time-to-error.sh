#!/usr/bin/env bash
# BENCHMARKS.md "Time to relMSE 1e-3 with every issue-12 knob": every scene of scenes/ (the
# Cornell box's mesh is in ../shared) through scripts/bench-sampling.sh, with the samplers,
# caustics, adaptive sampling, clamping and their combinations, in two runs of opposite orders
# per scene. Heavy scenes run at a reduced film (the spp to a relMSE target depends little on the
# film size; the times scale with it). A scene whose mesh or texture files are absent (the
# Cornell box's and the course's in ../shared beside the checkout) is skipped with a message.
#
#   scripts/bench-time-to-error.sh BUILD_DIR [OUT_DIR] [SCENE_NAME...]
set -euo pipefail
if [[ $# -lt 1 ]]; then
  echo "usage: scripts/bench-time-to-error.sh BUILD_DIR [OUT_DIR] [SCENE_NAME...]" >&2
  exit 2
fi
# BUILD_DIR and OUT_DIR are relative to the caller's directory, the scenes to the checkout's
build=$(realpath -m "$1")
out=$(realpath -m "${2:-bench-time-to-error}")
cd "$(dirname "$0")/.."
shift $(($# < 2 ? $# : 2))
only=" $* "
mkdir -p "$out"
delta="sampler=independent+no-caustics,no-caustics,caustics,adaptive+min-spp=8+no-caustics,no-caustics+clamp=10,caustics+clamp=10"
plain="sampler=independent,default,adaptive+min-spp=8,clamp=10,adaptive+min-spp=8+clamp=10"
# missing_assets SCENE: the absent files it names, where lucent looks for them
source "$(dirname "${BASH_SOURCE[0]}")/missing-assets.sh"
run() { # name scene ref_spp ladder settings args
  local name=$1 scene=$2 ref=$3 ladder=$4 settings=$5 args=$6
  [[ "$only" == "  " || "$only" == *" $name "* ]] || return 0
  [[ -f "$scene" ]] || { echo "== $name: $scene absent, skipped"; return 0; }
  local missing
  missing=$(missing_assets "$scene")
  [[ -z $missing ]] || { echo "== $name: $(head -1 <<<"$missing") absent, skipped"; return 0; }
  # a failed scene leaves no table that looks complete: the .md is written when it succeeded
  BENCH_SAMPLING_SETTINGS=$settings BENCH_SAMPLING_ARGS=$args BENCH_SAMPLING_CSV=$out \
    scripts/bench-sampling.sh "$build" "$ref" "$ladder" "$scene" | tee "$out/$name.md.part" ||
    { rm -f "$out/$name.md.part"; echo "bench-time-to-error: $name failed" >&2; exit 1; }
  mv "$out/$name.md.part" "$out/$name.md"
}
run whitted scenes/whitted.json 64 1,2,4,8 "sampler=independent,default" ""
run default scenes/default.json 1024 4,8,16,32,64,128,256 "$plain" ""
run textured scenes/textured.json 650 4,8,16,32,64,128 "$plain" ""
run depth-of-field scenes/depth-of-field.json 512 4,8,16,32,64 "$plain" "--width 320 --height 180"
run dragon-box scenes/dragon-box.json 1024 8,16,32,64,128,256 "$plain" "--width 200 --height 200"
run cornell-box scenes/cornell-box.json 1024 8,16,32,64,128,256 "$plain" "--width 200 --height 200"
run materials scenes/materials.json 2048 16,64,256,1024 "$delta" "--width 160 --height 90"
run rough-glass scenes/rough-glass.json 2048 16,64,256,1024 "$delta" "--width 160 --height 75"
run course scenes/course.json 4096 16,64,256,1024 "$delta" "--width 128 --height 128"
