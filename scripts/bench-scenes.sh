#!/usr/bin/env bash
# Render speed per scene: Msamples/s and Mrays/s at each scene's resolution with a fixed spp, and
# the kernel build time cold (empty lucent and PoCL caches) and warm (the same caches, second run),
# and the largest peak host memory (resident set) of the lucent process over the repetitions.
# Every figure is the best of RUNS repetitions (the machine is shared). Prints a Markdown table.
#
#   scripts/bench-scenes.sh [BUILD_DIR] [SPP] [RUNS]     (defaults: build, 16, 3)
#
# Scenes: scenes/*.json; those whose mesh or texture files are absent (the ../shared assets beside
# the checkout, which the scenes name as ../../shared/...) are skipped. Environment: LUCENT_DEVICE
# selects the device; LUCENT_BENCH_FLAGS adds render options (e.g. "--no-specialize" or
# "--fast-math").
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
spp=${2:-16}
runs=${3:-3}
lucent=$build/lucent
for v in "SPP $spp" "RUNS $runs"; do  # (RUNS 0 or a word printed a table of empty cells)
  [[ ${v#* } =~ ^[1-9][0-9]*$ ]] || { echo "bench-scenes: ${v% *} must be a positive number, got '${v#* }'" >&2; exit 2; }
done
[[ -x $lucent ]] || { echo "bench-scenes: $lucent not found (build the lucent_cli target)" >&2; exit 1; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# "out: WxH, N spp in S s (A Msamples/s, B Mrays/s, build C s, peak host memory M MiB) on DEVICE"
# -> "A B C M"
parse() {
  sed -n 's/.*spp in [0-9.]* s (\([0-9.]*\) Msamples\/s, \([0-9.]*\) Mrays\/s, build \([0-9.]*\) s, peak host memory \([0-9]*\) MiB) on .*/\1 \2 \3 \4/p' "$1"
}
min() { awk -v a="$1" -v b="$2" 'BEGIN { print (a == "" || b + 0 < a + 0) ? b : a }'; }

# missing_assets SCENE: the absent files it names, where lucent looks for them
source "$(dirname "${BASH_SOURCE[0]}")/missing-assets.sh"

device=""
echo "Machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores;" \
  "load average at start: $(cut -d' ' -f1-3 /proc/loadavg); $spp spp, best of $runs."
echo
echo "| scene | film | spp | Msamples/s | Mrays/s | rays/sample | build cold (s) | build warm (s) | peak host memory (MiB) |"
echo "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
for scene in "$root"/scenes/*.json; do
  name=$(basename "$scene" .json)
  missing=$(missing_assets "$scene")
  if [[ -n $missing ]]; then
    echo "| $name | | | (skipped: $(head -1 <<<"$missing") is absent) | | | | | |"
    continue
  fi
  best_ms="" best_mr="" best_cold="" best_warm="" film="" peak_mem=""
  for ((i = 0; i < runs; ++i)); do
    cache=$work/cache-$name-$i
    mkdir -p "$cache/lucent" "$cache/pocl"
    for pass in cold warm; do
      log=$work/log
      LUCENT_CACHE_DIR=$cache/lucent POCL_CACHE_DIR=$cache/pocl \
        "$lucent" render "$scene" --spp "$spp" ${LUCENT_BENCH_FLAGS:-} -o "$work/out.pfm" 2>"$log" >/dev/null ||
        { echo "bench-scenes: $name failed: $(tail -1 "$log")" >&2; exit 1; }
      read -r ms mr build_s mem < <(parse "$log") ||
        { echo "bench-scenes: $name: no summary line in lucent's output (-q in LUCENT_BENCH_FLAGS?)" >&2; exit 1; }
      peak_mem=$(awk -v a="$peak_mem" -v b="$mem" 'BEGIN { print (a == "" || b + 0 > a + 0) ? b : a }')
      film=$(sed -n 's/.*: \([0-9]*x[0-9]*\), .*/\1/p' "$log" | tail -1)
      device=$(sed -n 's/.* on \(.*\)$/\1/p' "$log" | tail -1)
      if [[ -z $best_ms ]] || awk -v a="$ms" -v b="$best_ms" 'BEGIN { exit !(a + 0 > b + 0) }'; then
        best_ms=$ms
        best_mr=$mr
      fi
      if [[ $pass == cold ]]; then best_cold=$(min "$best_cold" "$build_s"); fi
      if [[ $pass == warm ]]; then best_warm=$(min "$best_warm" "$build_s"); fi
    done
    rm -rf "$cache"
  done
  rps=$(awk -v a="$best_mr" -v b="$best_ms" 'BEGIN { printf "%.2f", (b > 0 ? a / b : 0) }')
  echo "| $name | $film | $spp | $best_ms | $best_mr | $rps | $best_cold | $best_warm | $peak_mem |"
done
echo
echo "Device: $device. Load average at the end: $(cut -d' ' -f1-3 /proc/loadavg)."
