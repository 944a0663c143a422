#!/bin/bash
# Renders a frame as a Slurm job array, then merges the results once all
# tasks have succeeded. Usage:
#   submit.sh N [VAR=value ...]          N independent passes (seeds 1..N)
#   submit.sh --tiles T [VAR=value ...]  a T x T grid of tiles of one render
# e.g.
#   contrib/slurm/submit.sh 16 SCENE=scenes/ring.toml RENDER_ARGS="--method sppm --iterations 256"
#   contrib/slurm/submit.sh --tiles 4 SCENE=scenes/cornell_box.toml RENDER_ARGS="--spp 16"
set -euo pipefail
here=$(dirname "$0")
if [ "${1:-}" = "--tiles" ]; then
    t=${2:?usage: submit.sh --tiles T [VAR=value ...]}
    shift 2
    export TILES=$t MODE=tiles
    script=tiles.sbatch
    n=$((t * t))
else
    n=${1:?usage: submit.sh N [VAR=value ...]}
    shift
    export MODE=passes
    script=seeds.sbatch
fi
for kv in "$@"; do export "${kv?}"; done
array=$(sbatch --parsable --export=ALL --array=1-"$n" "$here/$script")
# --parsable prints "id" or, on a multi-cluster setup, "id;cluster".
sbatch --export=ALL --dependency=afterok:"${array%%;*}" "$here/merge.sbatch"
