#!/usr/bin/env bash
# Plants each bug of docs/planted-bugs.md, one at a time, in a scratch copy of kernels/ (never in
# the tree), runs the whole CTest suite of a built tree against that copy (LUCENT_KERNEL_DIR, with
# private program caches) and lists the tests that failed.
#
#   scripts/planted-bugs.sh [--build DIR] [--jobs N] [--work DIR] [BUG...]
#
# BUG: baseline (the unmodified copy: every test must pass), 1 ... 7 (default: all of them).
# Results: WORK/<bug>.failed (one failing test per line) and WORK/<bug>.log (ctest's output).
# Each run starts from cold caches: about 2-3 minutes on two quiet cores.
set -euo pipefail
cd "$(dirname "$0")/.."
build=build jobs="" work=/tmp/lucent-planted
while [[ $# -gt 0 && "$1" == --* ]]; do
  [[ $# -ge 2 ]] || { echo "planted-bugs: $1 needs a value" >&2; exit 2; }
  case "$1" in
    --build) build="$2"; shift 2 ;;
    --jobs) jobs="$2"; shift 2 ;;
    --work) work="$2"; shift 2 ;;
    *) echo "planted-bugs: unknown option $1" >&2; exit 2 ;;
  esac
done
[[ -n "$jobs" ]] || jobs="$(scripts/cpus.sh)"
bugs=("$@")
[[ ${#bugs[@]} -gt 0 ]] || bugs=(baseline 1 2 3 4 5 6 7)
# every name checked before the first campaign (each one runs the whole suite for minutes)
for bug in "${bugs[@]}"; do
  [[ $bug =~ ^(baseline|[1-7])$ ]] || { echo "planted-bugs: unknown bug $bug (baseline, 1 ... 7)" >&2; exit 2; }
done
build="$(cd "$build" && pwd)"
mkdir -p "$work"

# plant BUG DIR: edit one line of the copy in DIR; fails when the line is not found
plant() {
  local file from to
  case "$1" in
    baseline) return 0 ;;
    1) file=bsdf/fresnel.cl from='return 0.5f * (rs * rs + rp * rp);' to='return rs * rs;' ;;
    2) file=integrator/path.cl from='beta * f * ls.L * (fabs(wi_l.z) * w / ls.pdf)'
       to='beta * f * ls.L * (w / ls.pdf)' ;;
    3) file=light/triangle.cl from='ls->pdf = L->pdf_select * d2 / (cos_l * L->p.triangle.area);'
       to='ls->pdf = L->pdf_select * d2 / L->p.triangle.area;' ;;
    4) file=util/math.cl
       from='static inline lc_real3 lc_spawn_origin(lc_real3 p, lc_real3 perr, lc_real3 n) {'
       to="$from return p + 1e-4f * n;" ;;
    5) file=integrator/path.cl from='beta /= q;' to='' ;;
    6) file=integrator/caustics.cl from='beta *= bs.weight * (bs.eta * bs.eta * corr);'
       to='beta *= bs.weight * corr;' ;;
    7) file=sampler/sampler.cl from='uint8 k = (uint8)(y.s0, z.s0, y.s1, z.s1, y.s2, z.s2, y.s3, z.s3);'
       to='uint8 k = (uint8)(y.s0, y.s0, y.s1, y.s1, y.s2, y.s2, y.s3, y.s3);' ;;
    *) echo "planted-bugs: unknown bug $1" >&2; return 1 ;;
  esac
  python3 - "$2/$file" "$from" "$to" <<'EOF'
import sys
path, old, new = sys.argv[1:]
text = open(path).read()
if text.count(old) != 1:
    sys.exit("planted-bugs: %s: expected one '%s', found %d" % (path, old, text.count(old)))
open(path, "w").write(text.replace(old, new))
EOF
}

for bug in "${bugs[@]}"; do
  dir="$work/$bug"
  rm -rf "$dir" && mkdir -p "$dir"
  cp -r kernels "$dir/kernels"
  plant "$bug" "$dir/kernels"
  echo "planted-bugs: $bug: $(diff -r kernels "$dir/kernels" | grep '^[<>]' | tr -s ' ' | head -2 | tr '\n' ' ')"
  (cd "$build" && LUCENT_KERNEL_DIR="$dir/kernels" POCL_CACHE_DIR="$dir/pocl-cache" \
     LUCENT_CACHE_DIR="$dir/lucent-cache" POCL_MAX_PTHREAD_COUNT=1 \
     ctest -j"$jobs" >"$work/$bug.log" 2>&1) || true
  sed -n 's/^[[:space:]]*[0-9]* - \(.*\) (\(Failed\|SEGFAULT\|Timeout\|Subprocess aborted\|Exception\).*/\1/p' \
    "$work/$bug.log" >"$work/$bug.failed"
  echo "planted-bugs: $bug: $(wc -l <"$work/$bug.failed") failed: $(tr '\n' ' ' <"$work/$bug.failed")"
done
