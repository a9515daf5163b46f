#!/usr/bin/env bash
# Submits a render split over a Slurm array job and the merge that follows it:
#
#   scripts/slurm/submit.sh SCENE SPP TASKS PARTS_DIR OUT [lucent render options]
#
# TASKS array tasks each render SPP/TASKS samples per pixel (render-part.sbatch); a merge job
# (merge.sbatch) waits for all of them (afterany) and writes OUT. Extra sbatch options for both:
# SBATCH_OPTS (e.g. "--partition=gpu --time=02:00:00"). Options of the merge (`lucent merge`):
# LUCENT_MERGE_OPTS (e.g. "--complete": the merge fails, writing nothing, when a task's samples
# are missing). Both are split at spaces, as a shell splits words (no quoting inside them).
# Prints the two job ids.
set -euo pipefail
if [[ $# -lt 5 ]]; then
  echo "usage: submit.sh SCENE SPP TASKS PARTS_DIR OUT [lucent render options]" >&2
  exit 2
fi
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
scene=$1 spp=$2 tasks=$3 parts=$4 out=$5
shift 5
# (at most Slurm's largest array, 4000001 tasks; digits counted first: bash's arithmetic wraps)
if ! [[ $tasks =~ ^[1-9][0-9]{0,6}$ ]] || ((tasks > 4000001)); then
  echo "submit: TASKS must be a number from 1 to 4000001, got '$tasks'" >&2
  exit 2
fi
# checked here too, before anything is queued (a leading zero read as octal split 010 as 8)
if ! [[ $spp =~ ^[1-9][0-9]*$ ]] || ((${#spp} > 10)) || ((spp < tasks)) ||
  ((spp > 4294967296)); then
  echo "submit: SPP must be a number of at least the $tasks tasks and at most 4294967296 (no" \
    "leading zero), got '$spp'" >&2
  exit 2
fi
# a part holds at most 2^24 samples (lucent render --samples): every task would fail
if (((spp + tasks - 1) / tasks > 16777216)); then
  echo "submit: $spp samples in $tasks tasks give a task more than the 16777216 samples a part" \
    "holds: use at least $(((spp + 16777215) / 16777216)) tasks" >&2
  exit 2
fi
# shellcheck disable=SC2086
# LUCENT_TASKS reaches the tasks through sbatch's default --export=ALL: each knows the split
array=$(LUCENT_TASKS=$tasks sbatch --parsable ${SBATCH_OPTS:-} --array="0-$((tasks - 1))" \
  "$here/render-part.sbatch" "$scene" "$spp" "$parts" "$@")
array=${array%%;*}  # "jobid;cluster" on federated clusters
# shellcheck disable=SC2086
merge=$(sbatch --parsable ${SBATCH_OPTS:-} --dependency="afterany:$array" \
  "$here/merge.sbatch" "$parts" "$out" --expect "0:$spp" ${LUCENT_MERGE_OPTS:-})
echo "render array job $array ($tasks tasks), merge job ${merge%%;*} -> $out"
