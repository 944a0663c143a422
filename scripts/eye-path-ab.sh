#!/bin/bash
# The fused eye path (the default) against the paper's pass per bounce
# (--faithful), direct light only, 16 spp at 256 x 192: for each scene, the
# two alternated, RUNS times; prints a Markdown table of the whole render's
# wall milliseconds (the stage table's total).
# usage: scripts/eye-path-ab.sh [RUNS] [SCENE...]
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-2}
shift || true
scenes=("${@:-cornell_box glass_ball ring variants/mesh_stage cornell_box_obj}")
bin=target/release/photonmap
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "| run | scene | eye paths | ms |"
echo "|---|---|---|---|"
for r in $(seq 1 "$runs"); do
  for sc in ${scenes[@]}; do
    for mode in "pass per bounce" fused; do
      flag=()
      [ "$mode" = "pass per bounce" ] && flag=(--faithful)
      ms=$("$bin" render "$sc" --width 256 --height 192 --direct-only --spp 16 "${flag[@]}" -o "$out/image.exr" 2>&1 | awk '/^total/ {print $4}')
      echo "| $r | $sc | $mode | $ms |"
    done
  done
done
