#!/usr/bin/env bash
# Sample splitting on one machine: the paths (camera samples) per second of one render run as 1
# and as 2 MPI ranks (lucent-mpi), alternated A B A B ... because the machine is shared, and the
# cost of merging part files. Prints Markdown.
#
#   scripts/bench-cluster.sh [BUILD_DIR] [SCENE] [SPP] [RUNS]   (defaults: build,
#                                                               scenes/default.json, 256, 3)
#
# Wall time of the whole mpirun (start, scene load, cached kernel load, render, reduce, write);
# paths/s = width * height * SPP / wall; and the CPU time of mpirun and its ranks, which the load
# of a shared machine does not change (paths per CPU second: what 2 ranks cost over 1). THREADS (default: PoCL's own choice) sets
# POCL_MAX_PTHREAD_COUNT per rank, e.g. THREADS=1 to give each rank one core.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
scene=${2:-$root/scenes/default.json}
spp=${3:-256}
runs=${4:-3}
[[ -x $build/lucent-mpi ]] || { echo "bench-cluster: $build/lucent-mpi not built (MPI)" >&2; exit 1; }
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_btl_vader_single_copy_mechanism=none
if [[ -n ${THREADS:-} ]]; then export POCL_MAX_PTHREAD_COUNT=$THREADS; fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

film=$("$build/lucent" info "$scene" | awk '$1 == "film" { print $2; exit }')
pixels=$(( ${film%x*} * ${film#*x} ))
# warm the kernel cache
"$build/lucent" render "$scene" --spp 1 -q -o "$work/warm.exr"

echo "Machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores;" \
  "$(basename "$scene") $film, $spp spp, threads per rank: ${THREADS:-PoCL default}."
echo
echo "| run | ranks | wall (s) | Mpaths/s | CPU (s) | Mpaths per CPU second | load average before |"
echo "| ---: | ---: | ---: | ---: | ---: | ---: | --- |"
for ((i = 1; i <= runs; i++)); do
  for np in 1 2; do
    load=$(cut -d' ' -f1-3 /proc/loadavg)
    # CPU: user + system of mpirun and the ranks (its children)
    /usr/bin/time -f "%e %U %S" -o "$work/time" \
      mpirun --oversubscribe -np "$np" "$build/lucent-mpi" "$scene" --spp "$spp" -q -o "$work/r$np.exr"
    read -r wall user sys <"$work/time"
    awk -v i="$i" -v np="$np" -v t="$wall" -v c="$(echo "$user + $sys" | bc)" \
      -v n="$((pixels * spp))" -v l="$load" \
      'BEGIN { printf "| %d | %d | %.2f | %.2f | %.2f | %.2f | %s |\n", i, np, t, n / t / 1e6, c, n / c / 1e6, l }'
  done
done

# merge: 8 parts of the same film, 2 spp each
echo
for ((k = 0; k < 8; k++)); do
  "$build/lucent" render "$scene" --samples "$((2 * k)):$((2 * k + 2))" -q -o "$work/part-$k.exr"
done
size=$(du -k "$work/part-0.exr" | cut -f1)
/usr/bin/time -f "%e %U %S %M" -o "$work/time" "$build/lucent" merge -q "$work"/part-*.exr -o "$work/merged.exr"
read -r wall user sys rss <"$work/time"
echo "Merge of 8 parts ($film, ${size} KiB each): wall ${wall} s, CPU $(echo "$user + $sys" | bc) s," \
  "peak memory $((rss / 1024)) MiB; load average after: $(cut -d' ' -f1-3 /proc/loadavg)."
