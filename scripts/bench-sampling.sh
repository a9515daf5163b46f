#!/usr/bin/env bash
# Time and spp to a relMSE target (default 1e-3) with the samplers, adaptive sampling and clamping
# (BENCHMARKS.md, "Samplers, adaptive sampling and clamping"), per scene, in two runs whose
# settings go in opposite orders (alternation: load drifts hit every setting alike).
#
#   scripts/bench-sampling.sh BUILD_DIR REF_SPP LADDER SCENE...
#   e.g. scripts/bench-sampling.sh build 1300 8,16,32,64,128,256 scenes/default.json
#
# Per scene: `lucent converge` with the settings below against one reference of REF_SPP spp
# (rendered once with the independent sampler and an independent seed, then reused), then per
# setting the relMSE minus the reference's own expected share (the CSV's
# reference_noise_relmse), the spp and time at which it crosses the target (log-log interpolation
# between rungs; when no rung reaches it, extrapolated from the top rung with the fitted slope and
# the top rung's samples per second, marked "ext. xK" with K the factor beyond the top rung), and
# the least-squares slope of that relMSE against spp. Environment: BENCH_SAMPLING_SETTINGS
# overrides the settings; BENCH_SAMPLING_TARGET the target; BENCH_SAMPLING_ARGS adds converge
# arguments (e.g. "--width 160 --height 90"); BENCH_SAMPLING_CSV=DIR keeps the two CSVs of each
# scene there (NAME.a.csv, NAME.b.csv).
set -euo pipefail
if [[ $# -lt 4 ]]; then
  echo "usage: scripts/bench-sampling.sh BUILD_DIR REF_SPP LADDER SCENE..." >&2
  exit 2
fi
build=$1 ref_spp=$2 ladder=$3
shift 3
[[ -x $build/lucent ]] || { echo "bench-sampling: $build/lucent not found (build the lucent_cli target)" >&2; exit 1; }
target=${BENCH_SAMPLING_TARGET:-1e-3}
settings=${BENCH_SAMPLING_SETTINGS:-sampler=independent,default,adaptive,clamp=2,adaptive+clamp=2}
reversed=$(echo "$settings" | tr ',' '\n' | tac | paste -sd, -)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export LUCENT_CACHE_DIR=${LUCENT_CACHE_DIR:-$build/lucent-cache}
for scene in "$@"; do
  name=$(basename "$scene" .json)
  echo "== $name (load $(cut -d' ' -f1-3 /proc/loadavg))"
  "$build/lucent" converge "$scene" --spp-ladder "$ladder" --reference-spp "$ref_spp" \
    --save-reference "$work/ref.exr" --settings "$settings" --csv "$work/a.csv" -q \
    ${BENCH_SAMPLING_ARGS:-} >/dev/null
  "$build/lucent" converge "$scene" --spp-ladder "$ladder" --reference "$work/ref.exr" \
    --settings "$reversed" --csv "$work/b.csv" -q ${BENCH_SAMPLING_ARGS:-} >/dev/null
  if [[ -n "${BENCH_SAMPLING_CSV:-}" ]]; then
    mkdir -p "$BENCH_SAMPLING_CSV"
    cp "$work/a.csv" "$BENCH_SAMPLING_CSV/$name.a.csv"
    cp "$work/b.csv" "$BENCH_SAMPLING_CSV/$name.b.csv"
  fi
  python3 - "$target" "$work/a.csv" "$work/b.csv" <<'PY'
import csv, math, sys
target = float(sys.argv[1])
def load(path):
    by = {}
    for r in csv.DictReader(open(path)):
        by.setdefault(r["setting"], []).append(
            (float(r["spp"]), float(r["seconds"]), float(r["relmse"]) - float(r["reference_noise_relmse"])))
    return by
def slope(pts):
    xs = [math.log(n) for n, t, e in pts if e > 0]; ys = [math.log(e) for n, t, e in pts if e > 0]
    if len(xs) < 2: return float("nan")
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
def crossing(pts):
    for i, (n, t, e) in enumerate(pts):
        if 0 < e <= target:
            if i == 0: return n, t, " (at most: the first rung)"
            n0, t0, e0 = pts[i - 1]
            if e0 <= 0 or e0 == e: return n, t, ""
            f = math.log(target / e0) / math.log(e / e0)
            return (math.exp(math.log(n0) + f * math.log(n / n0)),
                    math.exp(math.log(t0) + f * math.log(t / t0)), "")
    k = slope(pts)
    n, t, e = pts[-1] if pts else (0, 0, 0)
    if not (k < -0.1) or e <= 0: return None
    f = (target / e) ** (1.0 / k)  # samples beyond the top rung
    return n * f, t * f, " (ext. x%.1f)" % f
a, b = load(sys.argv[2]), load(sys.argv[3])
base = {}
print("| setting | relMSE at top rung (ref. share subtracted) | slope vs spp | spp to %g | time to %g, run A / run B (s) | time vs independent, A / B |" % (target, target))
print("| --- | ---: | ---: | ---: | ---: | ---: |")
for s in a:
    ca, cb = crossing(a[s]), crossing(b.get(s, []))
    if s.startswith("sampler=independent") and not base: base = {"a": ca, "b": cb}
    def ratio(c, k):
        return "%.2f" % (c[1] / base[k][1]) if c and base.get(k) else "-"
    print("| %s | %.3g | %.2f | %s | %s / %s | %s / %s |" % (
        s, a[s][-1][2], slope(a[s]), "%.0f" % ca[0] if ca else "-",
        ("%.2f" % ca[1]) + ca[2] if ca else "-", "%.2f" % cb[1] if cb else "-", ratio(ca, "a"), ratio(cb, "b")))
PY
done
echo "(load at the end $(cut -d' ' -f1-3 /proc/loadavg))"
