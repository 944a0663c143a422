#!/bin/bash
# Renders N independent passes of a frame as a Slurm job array, then merges
# them once all have succeeded. Usage: submit.sh N [VAR=value ...], e.g.
#   contrib/slurm/submit.sh 16 SCENE=scenes/ring.toml RENDER_ARGS="--method sppm --iterations 256"
set -euo pipefail
n=${1:?usage: submit.sh N [VAR=value ...]}
shift
for kv in "$@"; do export "${kv?}"; done
here=$(dirname "$0")
array=$(sbatch --parsable --export=ALL --array=1-"$n" "$here/seeds.sbatch")
# --parsable prints "id" or, on a multi-cluster setup, "id;cluster".
sbatch --export=ALL --dependency=afterok:"${array%%;*}" "$here/merge.sbatch"
