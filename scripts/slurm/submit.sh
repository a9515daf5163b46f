#!/usr/bin/env bash
# Submits a render split over a Slurm array job and the merge that follows it:
#
#   scripts/slurm/submit.sh SCENE SPP TASKS PARTS_DIR OUT [lucent render options]
#
# TASKS array tasks each render SPP/TASKS samples per pixel (render-part.sbatch); a merge job
# (merge.sbatch) waits for all of them (afterany) and writes OUT. Extra sbatch options for both:
# SBATCH_OPTS (e.g. "--partition=gpu --time=02:00:00"). Prints the two job ids.
set -euo pipefail
if [[ $# -lt 5 ]]; then
  echo "usage: submit.sh SCENE SPP TASKS PARTS_DIR OUT [lucent render options]" >&2
  exit 2
fi
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
scene=$1 spp=$2 tasks=$3 parts=$4 out=$5
shift 5
if ! [[ $tasks =~ ^[1-9][0-9]*$ ]]; then
  echo "submit: TASKS must be a positive number, got '$tasks'" >&2
  exit 2
fi
# checked here too, before anything is queued (a leading zero read as octal split 010 as 8)
if ! [[ $spp =~ ^[1-9][0-9]*$ ]] || ((spp < tasks)); then
  echo "submit: SPP must be a number of at least the $tasks tasks (no leading zero), got '$spp'" >&2
  exit 2
fi
# shellcheck disable=SC2086
# LUCENT_TASKS reaches the tasks through sbatch's default --export=ALL: each knows the split
array=$(LUCENT_TASKS=$tasks sbatch --parsable ${SBATCH_OPTS:-} --array="0-$((tasks - 1))" \
  "$here/render-part.sbatch" "$scene" "$spp" "$parts" "$@")
array=${array%%;*}  # "jobid;cluster" on federated clusters
# shellcheck disable=SC2086
merge=$(sbatch --parsable ${SBATCH_OPTS:-} --dependency="afterany:$array" \
  "$here/merge.sbatch" "$parts" "$out" --expect "0:$spp")
echo "render array job $array ($tasks tasks), merge job ${merge%%;*} -> $out"
