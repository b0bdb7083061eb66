#!/usr/bin/env bash
# Submits a Sahara frame to Slurm: an array job of N parts and a merge job
# that runs once every part has succeeded. Prints the two job ids.
#
#   farm/slurm/submit.sh N PARTS_DIR OUTPUT SCENE [RENDER OPTIONS...]
#
# Environment: SAHARA, SPLIT as for render-array.sbatch; SBATCH_OPTIONS,
# further sbatch options for both jobs (partition, account, time, ...).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
n=$1 parts_dir=$2 output=$3 scene=$4
shift 4
# shellcheck disable=SC2086
render=$(sbatch --parsable ${SBATCH_OPTIONS:-} --array="0-$((n - 1))" \
    "$here/render-array.sbatch" "$n" "$parts_dir" "$scene" "$@")
render=${render%%;*}
# shellcheck disable=SC2086
merge=$(sbatch --parsable ${SBATCH_OPTIONS:-} --dependency="afterok:$render" \
    "$here/merge.sbatch" "$n" "$parts_dir" "$output")
echo "$render $merge"
