#!/usr/bin/env bash
# lucent against Blender Cycles (CPU) on the McGuire Cornell box: paths/s of both renderers on the
# same scene (scenes/cornell-box.json's OBJ and camera), the same film size, max depth and spp,
# in alternating runs (Cycles, lucent, Cycles, lucent, ...), and the mean of both linear images.
#
#   scripts/bench-cycles.sh [BUILD_DIR] [SPP] [PAIRS] [SIZE]     (defaults: build, 256, 2, 256)
#
# A benchmark-only dependency: needs `blender` (Debian's package; 3.4 was used) and the shared
# asset ../shared/assets/cornell-box/CornellBox-Original.obj; skips with a message (exit 0) when
# either is absent. Cycles settings: bench/cycles/cornell_box.py (2 threads, max_bounces =
# max_depth - 2 for every bounce type, no denoising, no adaptive sampling, no clamping).
# lucent runs on its default OpenCL device with POCL_MAX_PTHREAD_COUNT=2 (2 threads on PoCL).
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
spp=${2:-256}
pairs=${3:-2}
size=${4:-256}
threads=2
max_depth=8
lucent=$build/lucent
scene=$root/scenes/cornell-box.json

if ! command -v blender >/dev/null; then
  echo "bench-cycles: skipped: blender is not installed (apt-get install blender)"
  exit 0
fi
# the OBJ that lucent renders: the scene's mesh, relative to scenes/ (../shared beside the
# checkout; a /work/shared elsewhere gave Cycles a mesh while lucent failed on its own)
obj=$(grep -o '"file": *"[^"]*"' "$scene" | head -1 | sed 's/.*: *"\(.*\)"$/\1/')
[[ $obj == /* ]] || obj=$(realpath -m "$root/scenes/$obj")
if [[ ! -f $obj ]]; then
  echo "bench-cycles: skipped: $obj is absent"
  exit 0
fi
[[ -x $lucent ]] || { echo "bench-cycles: $lucent not found (build the lucent_cli target)" >&2; exit 1; }
grep -q "\"max_depth\": $max_depth" "$scene" ||
  { echo "bench-cycles: $scene no longer has max_depth $max_depth" >&2; exit 1; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export LUCENT_CACHE_DIR=$work/lucent-cache POCL_CACHE_DIR=$work/pocl-cache
export POCL_MAX_PTHREAD_COUNT=$threads

now() { date +%s.%N; }
# "MM:SS.ss" or "HH:MM:SS.ss" -> seconds
secs() { awk -F: '{ s = 0; for (i = 1; i <= NF; ++i) s = s * 60 + $i; print s }' <<<"$1"; }
# mean of the three channels of a PFM image
pfm_mean() {
  python3 - "$1" <<'EOF'
import struct, sys
with open(sys.argv[1], "rb") as f:
    kind = f.readline().strip()
    w, h = map(int, f.readline().split())
    scale = float(f.readline())
    data = f.read()
ch = 3 if kind == b"PF" else 1
fmt = ("<" if scale < 0 else ">") + "%df" % (w * h * ch)
px = struct.unpack(fmt, data[: w * h * ch * 4])
m = [sum(px[c::ch]) / (w * h) for c in range(ch)]
print("R %.5f G %.5f B %.5f, average %.5f" % (m[0], m[1], m[2], sum(m) / 3))
EOF
}

run_cycles() {  # -> "sampling_s wall_s mean..." in $work/cycles.res, full log in $work/cycles.log
  local t0 t1
  t0=$(now)
  blender -b -noaudio --factory-startup -P "$root/bench/cycles/cornell_box.py" -- \
    --obj "$obj" --scene "$scene" --size "$size" --spp "$spp" --threads "$threads" \
    --max-depth "$max_depth" --output "$work/cycles.exr" >"$work/cycles.log" 2>&1 ||
    { echo "bench-cycles: blender failed: $(tail -3 "$work/cycles.log")" >&2; exit 1; }
  t1=$(now)
  local start end
  start=$(sed -n "s/.*| Time:\([0-9:.]*\) .*| Sample 0\/$spp\$/\1/p" "$work/cycles.log" | head -1)
  end=$(sed -n "s/.*| Time:\([0-9:.]*\) .*| Sample $spp\/$spp\$/\1/p" "$work/cycles.log" | tail -1)
  [[ -n $start && -n $end ]] ||
    { echo "bench-cycles: no 'Sample 0/$spp' or 'Sample $spp/$spp' status in Blender's log" >&2; exit 1; }
  cyc_sync=$(secs "$start")
  cyc_sampling=$(awk -v a="$(secs "$start")" -v b="$(secs "$end")" 'BEGIN { printf "%.3f", b - a }')
  cyc_call=$(sed -n 's/^cycles: render call .* \([0-9.]*\) s: .*/\1/p' "$work/cycles.log")
  cyc_process=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f", b - a }')
  cyc_mean=$(sed -n 's/^cycles: image mean (linear) //p' "$work/cycles.log")
}

run_lucent() {
  local t0 t1 log=$work/lucent.log
  t0=$(now)
  "$lucent" render "$scene" --width "$size" --height "$size" --spp "$spp" \
    -o "$work/lucent.pfm" >/dev/null 2>"$log" ||
    { echo "bench-cycles: lucent failed: $(tail -1 "$log")" >&2; exit 1; }
  t1=$(now)
  luc_render=$(sed -n 's/.*spp in \([0-9.]*\) s (.*/\1/p' "$log" | tail -1)
  luc_build=$(sed -n 's/.*, build \([0-9.]*\) s, .*/\1/p' "$log" | tail -1)
  luc_process=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f", b - a }')
  luc_device=$(sed -n 's/.* on \(.*\)$/\1/p' "$log" | tail -1)
  luc_mean=$(pfm_mean "$work/lucent.pfm")
}

mps() { awk -v n="$((size * size * spp))" -v t="$1" 'BEGIN { printf "%.3f", n / t * 1e-6 }'; }

echo "Machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores;" \
  "load average at start: $(cut -d' ' -f1-3 /proc/loadavg)."
echo "$(blender -b -noaudio --factory-startup --version 2>/dev/null | head -1); scene: $obj with" \
  "the camera of scenes/cornell-box.json; ${size}x$size, $spp spp, max_depth $max_depth" \
  "(Cycles max_bounces $((max_depth - 2))), $threads threads."
run_lucent  # warm-up: builds the kernel into the (new) caches
echo "lucent warm-up (cold kernel build $luc_build s) on $luc_device."
echo
echo "| run | renderer | sampling time (s) | Mpaths/s (sampling) | process wall (s) | Mpaths/s (wall) | load average |"
echo "| ---: | --- | ---: | ---: | ---: | ---: | --- |"
best_c="" best_l=""
for ((i = 1; i <= pairs; ++i)); do
  run_cycles
  c=$(mps "$cyc_sampling")
  echo "| $i | Cycles | $cyc_sampling (sync $cyc_sync, render call $cyc_call) | $c | $cyc_process | $(mps "$cyc_process") | $(cut -d' ' -f1 /proc/loadavg) |"
  run_lucent
  l=$(mps "$luc_render")
  echo "| $i | lucent | $luc_render (kernel build $luc_build, cached) | $l | $luc_process | $(mps "$luc_process") | $(cut -d' ' -f1 /proc/loadavg) |"
  best_c=$(awk -v a="$best_c" -v b="$c" 'BEGIN { print (a == "" || b + 0 > a + 0) ? b : a }')
  best_l=$(awk -v a="$best_l" -v b="$l" 'BEGIN { print (a == "" || b + 0 > a + 0) ? b : a }')
done
echo
echo "Best Mpaths/s (sampling time): Cycles $best_c, lucent $best_l; lucent/Cycles" \
  "$(awk -v a="$best_l" -v b="$best_c" 'BEGIN { printf "%.2f", a / b }')."
echo "Image means (linear): Cycles $cyc_mean; lucent $luc_mean."
echo "Load average at the end: $(cut -d' ' -f1-3 /proc/loadavg)."
