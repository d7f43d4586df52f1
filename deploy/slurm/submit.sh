#!/bin/sh
# Submits obscura's Slurm jobs (frames.sbatch, bake.sbatch beside this
# script) and prints their job ids, one per line:
#
#   submit.sh frames FIRST LAST CHUNK [sbatch options...]
#       OBSCURA_INPUT, OBSCURA_OUTPUT (and OBSCURA_CAMERA, OBSCURA_ARGS, ...)
#       from the environment; one array task per CHUNK frames
#   submit.sh bake|bake-dynamic LEVEL OUTPUT SHARDS [sbatch options...]
#       PARTS, TRACE_ARGS, MERGE_ARGS from the environment; an array of
#       SHARDS shard tasks, then the merge with --dependency=afterok on it
#
# The sbatch options (--partition, --cpus-per-task, --mem, --chdir, ...)
# go to every job submitted; the templates' #SBATCH lines are defaults.
#   SBATCH         the sbatch command (default: sbatch on PATH)
#   OBSCURA_SLURM  the folder of the templates (default: this script's)
set -eu
usage() {
    echo "usage: $0 frames FIRST LAST CHUNK [sbatch options...]" >&2
    echo "       $0 bake|bake-dynamic LEVEL OUTPUT SHARDS [sbatch options...]" >&2
    exit 2
}
dir=${OBSCURA_SLURM:-$(dirname "$0")}
sb=${SBATCH:-sbatch}
[ $# -ge 4 ] || usage
kind=$1
case $kind in
frames)
    FIRST=$2 LAST=$3 CHUNK=$4
    shift 4
    [ "$CHUNK" -ge 1 ] && [ "$LAST" -ge "$FIRST" ] || usage
    export FIRST LAST CHUNK
    $sb --parsable --array=0-$(((LAST - FIRST) / CHUNK)) "$@" "$dir/frames.sbatch"
    ;;
bake | bake-dynamic)
    LEVEL=$2 OUTPUT=$3 SHARDS=$4 BAKE=$kind
    shift 4
    [ "$SHARDS" -ge 1 ] || usage
    export LEVEL OUTPUT SHARDS BAKE
    shards=$($sb --parsable --job-name="obscura-$kind-shard" --array=0-$((SHARDS - 1)) "$@" "$dir/bake.sbatch")
    echo "$shards"
    $sb --parsable --job-name="obscura-$kind-merge" --dependency=afterok:"${shards%%;*}" \
        --kill-on-invalid-dep=yes "$@" "$dir/bake.sbatch"
    ;;
*) usage ;;
esac
