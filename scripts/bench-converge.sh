#!/usr/bin/env bash
# Time to reach a relMSE target (default 1e-3) against a high-spp reference, per scene, with
# `lucent converge` (BENCHMARKS.md, "Time to relMSE 1e-3"). Prints a Markdown table.
#
#   scripts/bench-converge.sh [BUILD_DIR] [TARGET] [REF_FACTOR] [MAX_SECONDS]
#                             (defaults: build, 1e-3, 8, 90)
#
# Per scene, at the scene's own resolution and settings:
#  1. a pilot (`lucent converge --spp-ladder 8 --reference-spp 8`) estimates the error per sample
#     c from the images' own per-pixel variances (relMSE explained by noise, about c/spp) and the
#     render time per spp, hence N* = c / TARGET, the spp predicted to reach the target;
#  2. a ladder of powers of two from 1 to the first one >= 1.2 N* (capped so that the top rung
#     takes at most MAX_SECONDS; the scene is then marked "extrapolated"), against a reference of
#     REF_FACTOR x N* spp (REF_FACTOR x the top rung when capped), rendered by `lucent converge`
#     with an independent seed;
#  3. every rung's relMSE minus the reference's own share of the error: the reference has the same
#     per-pixel variance per sample as the rung, so of the noise relMSE explained by both
#     (the CSV's noise_relmse) the fraction spp / (spp + ref_spp) is the reference's. With
#     REF_FACTOR 8 that share is about 11% of the target at N*; it is subtracted, not ignored;
#  4. the spp and render time (kernel build excluded) at which the corrected relMSE crosses the
#     target, interpolated linearly on log-log axes between the two rungs around it, or, when no
#     rung reaches it, extrapolated from the top rung with the least-squares slope of relMSE
#     against spp over all rungs (time: at the top rung's samples per second).
#
# Scenes: scenes/*.json; those whose mesh or texture files are absent (the ../shared assets beside
# the checkout, which the scenes name as ../../shared/...) are skipped.
# Environment: LUCENT_DEVICE selects the device; BENCH_CONVERGE_SCENES="a b" limits the scenes;
# BENCH_CONVERGE_KEEP=DIR keeps each scene's ladder CSV as DIR/SCENE.csv.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
target=${2:-1e-3}
ref_factor=${3:-8}
max_seconds=${4:-90}
lucent=$build/lucent
for v in "TARGET $target" "REF_FACTOR $ref_factor" "MAX_SECONDS $max_seconds"; do
  python3 -c 'import math, sys; v = float(sys.argv[1]); sys.exit(not (math.isfinite(v) and v > 0))' \
    "${v#* }" 2>/dev/null ||
    { echo "bench-converge: ${v% *} must be a positive number, got '${v#* }'" >&2; exit 2; }
done
[[ -x $lucent ]] || { echo "bench-converge: $lucent not found (build the lucent_cli target)" >&2; exit 1; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export LUCENT_CACHE_DIR=${LUCENT_CACHE_DIR:-$build/lucent-cache}
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$build/pocl-cache}

# missing_assets SCENE: the absent files it names, where lucent looks for them
source "$(dirname "${BASH_SOURCE[0]}")/missing-assets.sh"

# pilot CSV -> "N* seconds_per_spp"
plan() {
  python3 - "$1" "$target" <<'EOF'
import csv, sys
row = list(csv.DictReader(open(sys.argv[1])))[-1]
spp, noise = float(row["spp"]), float(row["noise_relmse"])
# noise = c/spp (image) + c/spp (reference of the same spp)
c = noise * spp / 2
print("%.6g %.6g" % (c / float(sys.argv[2]), float(row["seconds"]) / spp))
EOF
}

# full CSV -> one Markdown row tail
analyse() {
  python3 - "$1" "$target" "$2" "$3" "$max_seconds" <<'EOF'
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
target, ref_spp, capped = float(sys.argv[2]), float(sys.argv[3]), sys.argv[4] == "1"
pts = []
for r in rows:
    n, t, e, noise = (float(r[k]) for k in ("spp", "seconds", "relmse", "noise_relmse"))
    ref_share = noise * n / (n + ref_spp)  # the reference's own noise in this rung's relMSE
    pts.append((n, t, e - ref_share, e, noise - ref_share, float(r["samples_per_s"])))

def loglog(x1, y1, x2, y2, y):
    if y1 <= 0 or y2 <= 0 or y1 == y2:
        return float("nan")
    return math.exp(math.log(x1) + (math.log(y) - math.log(y1)) *
                    (math.log(x2) - math.log(x1)) / (math.log(y2) - math.log(y1)))

def slope(xs, ys):
    # nan below two distinct rungs (a ladder of 1 spp alone when the target needs less)
    if len(set(xs)) < 2:
        return float("nan")
    lx = [math.log(x) for x in xs]; ly = [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)

how, n_hit, t_hit = "", float("nan"), float("nan")
top = pts[-1]
for i in range(1, len(pts)):
    a, b = pts[i - 1], pts[i]
    if a[2] > target >= b[2]:
        n_hit = loglog(a[0], a[2], b[0], b[2], target)
        t_hit = loglog(a[1], a[2], b[1], b[2], target)
        how = "interpolated (%d-%d spp)" % (a[0], b[0])
        break
if not how:
    if pts[0][2] <= target:
        n_hit, t_hit, how = pts[0][0], pts[0][1], "reached at the first rung"
    else:
        # the least-squares slope over all rungs (the last few alone are noisy where fireflies
        # dominate), from the top rung; time at the top rung's samples per second
        fitted = [p for p in pts if p[2] > 0]
        sn = slope([p[0] for p in fitted], [p[2] for p in fitted])
        n_hit = top[0] * (target / top[2]) ** (1 / sn) if sn < 0 else float("inf")
        t_hit = top[1] * n_hit / top[0]
        how = "**extrapolated** from the top rung with the slope fitted over all rungs (%.2f)%s" % (
            sn, ", top rung capped at %g s" % float(sys.argv[5]) if capped else "")
fit = slope([p[0] for p in pts if p[2] > 0], [p[2] for p in pts if p[2] > 0])
# cross-check: the spp at which the rung's own noise (no reference) falls to the target
noise_n = top[0] * top[4] / target
print("%d | %.3g | %.3g (%.2e) | %.0f | %.3g | %.2f | %.2f | %.0f | %s" % (
    ref_spp, top[0], top[2], top[3] - top[2], n_hit, t_hit, top[5] * 1e-6, fit, noise_n, how))
EOF
}

echo "Machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores;" \
  "load average at start: $(cut -d' ' -f1-3 /proc/loadavg); target relMSE $target, reference" \
  "$ref_factor x the predicted spp, top rung capped at $max_seconds s."
echo
echo "| scene | film | reference spp | top rung spp | relMSE at the top rung, corrected (reference share) | spp to target | time to target (s) | Msamples/s (top rung) | slope vs spp | spp to target from the noise estimate | how |"
echo "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |"
start=$(date +%s)
for scene in "$root"/scenes/*.json; do
  name=$(basename "$scene" .json)
  if [[ -n ${BENCH_CONVERGE_SCENES:-} && " $BENCH_CONVERGE_SCENES " != *" $name "* ]]; then continue; fi
  missing=$(missing_assets "$scene")
  if [[ -n $missing ]]; then
    echo "| $name | (skipped: $(head -1 <<<"$missing") is absent) | | | | | | | | | |"
    continue
  fi
  film=$(grep -o '"width": *[0-9]*, *"height": *[0-9]*' "$scene" | sed 's/[^0-9,]//g; s/,/×/')
  "$lucent" converge "$scene" --spp-ladder 8 --reference-spp 8 --csv "$work/pilot.csv" -q \
    >/dev/null 2>"$work/log" || { echo "bench-converge: $name pilot failed: $(tail -1 "$work/log")" >&2; exit 1; }
  read -r nstar sec_per_spp < <(plan "$work/pilot.csv")
  read -r top capped ref_spp < <(awk -v n="$nstar" -v s="$sec_per_spp" -v tmax="$max_seconds" \
    -v k="$ref_factor" 'BEGIN {
      top = 1; while (top < 1.2 * n) top *= 2;
      capped = 0; while (top > 1 && top * s > tmax) { top /= 2; capped = 1 }
      ref = capped ? k * top : k * n; if (ref < 64) ref = 64;
      printf "%d %d %d\n", top, capped, int(ref + 0.5) }')
  ladder=1
  for ((s = 2; s <= top; s *= 2)); do ladder+=",$s"; done
  "$lucent" converge "$scene" --spp-ladder "$ladder" --reference-spp "$ref_spp" \
    --csv "$work/full.csv" -q >/dev/null 2>"$work/log" ||
    { echo "bench-converge: $name failed: $(tail -1 "$work/log")" >&2; exit 1; }
  if [[ -n ${BENCH_CONVERGE_KEEP:-} ]]; then mkdir -p "$BENCH_CONVERGE_KEEP" && cp "$work/full.csv" "$BENCH_CONVERGE_KEEP/$name.csv"; fi
  # (a failing analysis stops here: in echo's arguments it printed a row of empty cells)
  row=$(analyse "$work/full.csv" "$ref_spp" "$capped" "$max_seconds")
  echo "| $name | $film | $row |"
done
echo
echo "Total $(($(date +%s) - start)) s. Load average at the end: $(cut -d' ' -f1-3 /proc/loadavg)."
