#!/usr/bin/env bash
# lucent against Mitsuba 3 (variant llvm_ad_rgb, CPU) on the same scenes: paths/s of both
# renderers in alternating runs (Mitsuba, lucent, Mitsuba, lucent, ...), their ratio and the means
# of both linear images.
#
#   scripts/bench-mitsuba.sh [BUILD_DIR] [SPP] [PAIRS] [SIZE]     (defaults: build, 64, 3, 256)
#   BENCH_MITSUBA_SCENES="cornell-box default dragon-box"          (scenes/NAME.json, the default)
#   BENCH_LUCENT_SAMPLER=independent    lucent's sampler, as Mitsuba's (default: lucent's own, sobol,
#                                       which costs 11-19% more per path; BENCHMARKS.md)
#   BENCH_MITSUBA_VARIANT=cuda_ad_rgb    Mitsuba's variant (default llvm_ad_rgb); with a GPU variant
#                                       lucent renders on LUCENT_DEVICE (default: the first GPU)
#
# Each scene is rendered SIZE x SIZE with a box filter (radius 0.5), SPP samples per pixel, its own
# max_depth (cornell-box and dragon-box 8, default 6), Russian roulette at each renderer's default,
# 2 threads. bench/mitsuba/bench_mitsuba.py writes lucent's copy of the scene (film and filter
# overridden) and builds Mitsuba's from the same JSON with the dict API (diffuse materials,
# spheres, meshes, point lights, constant environment; docs in that file).
#
# Times: Mitsuba's is its second mi.render() call in one process (the first traces and compiles
# the kernels, or loads them from Dr.Jit's cache), until the image is evaluated; lucent's is
# RenderResult::seconds (kernel passes and host accumulation; the kernel comes from the binary
# cache, warmed before the first pair). paths/s = SIZE^2 x SPP / time.
# CPU time, which a loaded machine disturbs far less than wall time (both renderers use 2 threads,
# so on an idle machine wall Mpaths/s ~ 2 x Mpaths per CPU second): Mitsuba's is the process's
# user + system time across its timed render (every thread); lucent's is its process's user +
# system time minus that of a 1-spp render of the same scene (start-up, scene load, BVH build,
# kernel from the cache), scaled by SPP / (SPP - 1).
#
# A benchmark-only dependency, installed by hand, never by this script:
#   pip install mitsuba                      # 3.9.1 with drjit 1.5.0 was used
#   apt-get install libllvm19                # Debian 12: the LLVM that variant llvm_ad_rgb needs
# Dr.Jit loads the newest /usr/lib/x86_64-linux-gnu/libLLVM*.so.* it finds (DRJIT_LIBLLVM_PATH
# overrides). Debian 12's libllvm14 is refused (Dr.Jit 1.5 needs LLVM >= 15); libllvm15 (PoCL's)
# and libllvm16 load but abort on the first render ("LLVM ERROR: Cannot select ... fminimum"):
# the x86 backend of LLVM < 17 cannot lower the fminimum that Dr.Jit emits. libllvm19 works.
# The script skips (exit 0) with a message when mitsuba is not importable, when llvm_ad_rgb
# cannot render, or (per scene) when a scene's ../shared asset is absent.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
spp=${2:-64}
pairs=${3:-3}
size=${4:-256}
threads=2
variant=${BENCH_MITSUBA_VARIANT:-llvm_ad_rgb}
scenes=${BENCH_MITSUBA_SCENES:-cornell-box default dragon-box}
helper=$root/bench/mitsuba/bench_mitsuba.py
lucent=$build/lucent
# SPP >= 2: lucent's CPU time is that of the run minus a 1-spp run, scaled by SPP / (SPP - 1)
for v in "SPP $spp 2" "PAIRS $pairs 1" "SIZE $size 1"; do
  read -r what val least <<<"$v"
  [[ $val =~ ^[1-9][0-9]*$ ]] && ((val >= least)) ||
    { echo "bench-mitsuba: $what must be a whole number of at least $least, got '$val'" >&2; exit 2; }
done

if ! python3 -c 'import mitsuba' >/dev/null 2>&1; then
  echo "bench-mitsuba: skipped: python3 cannot import mitsuba (pip install mitsuba)"
  exit 0
fi
probe=$(python3 -c '
import drjit as dr, mitsuba as mi
import sys
mi.set_variant(sys.argv[1])
img = mi.render(mi.load_dict(mi.cornell_box()), spp=1)
dr.eval(img)
print("ok")' "$variant" 2>&1 | tail -1 || true)
if [[ $probe != ok ]]; then
  echo "bench-mitsuba: skipped: Mitsuba's $variant variant cannot render here ($probe);" \
    "it needs libLLVM >= 17 (Debian 12: apt-get install libllvm19)"
  exit 0
fi
[[ -x $lucent ]] || { echo "bench-mitsuba: $lucent not found (build the lucent_cli target)" >&2; exit 1; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export LUCENT_CACHE_DIR=$work/lucent-cache POCL_CACHE_DIR=$work/pocl-cache
export POCL_MAX_PTHREAD_COUNT=$threads

now() { date +%s.%N; }
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
mps() { awk -v n="$((size * size * spp))" -v t="$1" 'BEGIN { printf "%.3f", n / t * 1e-6 }'; }
load1() { cut -d' ' -f1 /proc/loadavg; }

run_mitsuba() {  # $1 scene json, $2 max_depth
  local t0 t1 log=$work/mitsuba.log
  t0=$(now)
  python3 "$helper" render "$1" --size "$size" "$size" --spp "$spp" --max-depth "$2" \
    --threads "$threads" --variant "$variant" >"$log" 2>&1 ||
    { echo "bench-mitsuba: mitsuba failed: $(tail -3 "$log")" >&2; exit 1; }
  t1=$(now)
  mi_render=$(sed -n 's/^mitsuba: render seconds //p' "$log")
  mi_cpu=$(sed -n 's/^mitsuba: render CPU seconds \([0-9.]*\) .*/\1/p' "$log")
  mi_exec=$(sed -n 's/.*execution \([0-9.]*\) s: .*/\1/p' "$log")
  mi_process=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f", b - a }')
  mi_mean=$(sed -n 's/^mitsuba: image mean (linear) //p' "$log")
  mi_header=$(sed -n '1s/^mitsuba: //p' "$log")
}

run_lucent() {  # $1 lucent scene json [$2 extra option]; CPU seconds of the process in luc_cpu
  local t0 t1 log=$work/lucent.log TIMEFORMAT='%U %S'
  t0=$(now)
  { time "$lucent" render "$1" ${2:-} -o "$work/lucent.pfm" >/dev/null 2>"$log" ; } 2>"$work/cpu" ||
    { echo "bench-mitsuba: lucent failed: $(tail -1 "$log")" >&2; exit 1; }
  t1=$(now)
  luc_cpu=$(awk '{ print $1 + $2 }' "$work/cpu")
  luc_render=$(sed -n 's/.*spp in \([0-9.]*\) s (.*/\1/p' "$log" | tail -1)
  luc_build=$(sed -n 's/.*, build \([0-9.]*\) s, .*/\1/p' "$log" | tail -1)
  luc_rays=$(sed -n 's/.*Msamples\/s, \([0-9.]*\) Mrays\/s.*/\1/p' "$log" | tail -1)
  luc_process=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.3f", b - a }')
  luc_device=$(sed -n 's/.* on \(.*\)$/\1/p' "$log" | tail -1)
  luc_mean=$(pfm_mean "$work/lucent.pfm")
}

echo "Machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores;" \
  "load average at start: $(cut -d' ' -f1-3 /proc/loadavg)."
echo "lucent $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo '?') (sampler: ${BENCH_LUCENT_SAMPLER:-scene default}); ${size}x$size, $spp spp," \
  "box filter, $threads threads; $pairs alternating pairs per scene."
for name in $scenes; do
  scene=$root/scenes/$name.json
  [[ -f $scene ]] || { echo "bench-mitsuba: $scene not found" >&2; exit 1; }
  missing=$(python3 - "$scene" <<'EOF'
import json, os, sys
s = json.load(open(sys.argv[1]))
d = os.path.dirname(os.path.abspath(sys.argv[1]))
print(" ".join(sh["file"] for sh in s.get("shapes", [])
               if "file" in sh and not os.path.exists(os.path.join(d, sh["file"]))))
EOF
)
  if [[ -n $missing ]]; then
    echo
    echo "bench-mitsuba: $name skipped: $missing is absent"
    continue
  fi
  max_depth=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1])).get("integrator", {}).get("max_depth", 5))' "$scene")
  python3 "$helper" lucent-scene "$scene" "$work/$name.json" --size "$size" "$size" --spp "$spp" \
    --max-depth "$max_depth" ${BENCH_LUCENT_SAMPLER:+--sampler "$BENCH_LUCENT_SAMPLER"}
  run_lucent "$work/$name.json"  # warm-up: builds the kernel into the (new) caches
  first_build=$luc_build
  run_lucent "$work/$name.json" "--spp 1"  # the fixed CPU cost of a run, for lucent's CPU time
  base_cpu=$luc_cpu
  echo
  echo "### $name (max_depth $max_depth)"
  echo
  echo "lucent warm-up (first run in this run's fresh caches; scenes with the same features share a kernel): kernel build $first_build s on $luc_device; CPU of a 1-spp run $base_cpu s."
  echo
  echo "| pair | Mitsuba render (s) | Mitsuba Mpaths/s | lucent render (s) | lucent Mpaths/s | lucent Mrays/s | lucent/Mitsuba (wall) | Mpaths per CPU s, Mitsuba / lucent | lucent/Mitsuba (CPU) | process wall Mitsuba / lucent (s) | load average |"
  echo "| ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- | ---: | --- | --- |"
  ratios=() cratios=()
  best_m="" best_l=""
  for ((i = 1; i <= pairs; ++i)); do
    la=$(load1)
    run_mitsuba "$scene" "$max_depth"
    run_lucent "$work/$name.json"
    m=$(mps "$mi_render")
    l=$(mps "$luc_render")
    r=$(awk -v a="$l" -v b="$m" 'BEGIN { printf "%.3f", a / b }')
    ratios+=("$r")
    mc=$(mps "$mi_cpu")
    lc=$(awk -v c="$luc_cpu" -v b="$base_cpu" -v s="$spp" -v n="$((size * size * spp))" \
      'BEGIN { t = (c - b) * s / (s - 1); printf "%.3f", (t > 0 ? n / t * 1e-6 : 0) }')
    cr=$(awk -v a="$lc" -v b="$mc" 'BEGIN { printf "%.3f", a / b }')
    cratios+=("$cr")
    echo "| $i | $mi_render (kernel execution $mi_exec) | $m | $luc_render | $l | $luc_rays | $r | $mc / $lc | $cr | $mi_process / $luc_process | $la-$(load1) |"
    best_m=$(awk -v a="$best_m" -v b="$m" 'BEGIN { print (a == "" || b + 0 > a + 0) ? b : a }')
    best_l=$(awk -v a="$best_l" -v b="$l" 'BEGIN { print (a == "" || b + 0 > a + 0) ? b : a }')
  done
  med() { printf '%s\n' "$@" | sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
  median=$(med "${ratios[@]}")
  cmedian=$(med "${cratios[@]}")
  echo
  echo "Mitsuba: $mi_header."
  echo "Ratio lucent/Mitsuba: median $median over $pairs pairs (range $(printf '%s\n' "${ratios[@]}" | sort -g | head -1)-$(printf '%s\n' "${ratios[@]}" | sort -g | tail -1));" \
    "best Mpaths/s: Mitsuba $best_m, lucent $best_l; in CPU time: median $cmedian (range" \
    "$(printf '%s\n' "${cratios[@]}" | sort -g | head -1)-$(printf '%s\n' "${cratios[@]}" | sort -g | tail -1))."
  echo "Image means (linear, last pair): Mitsuba $mi_mean; lucent $luc_mean."
done
echo
echo "Load average at the end: $(cut -d' ' -f1-3 /proc/loadavg)."
