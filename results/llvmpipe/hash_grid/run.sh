#!/bin/sh
# The hash-grid measurements of README "The hash grid (section 4.4)".
# llvmpipe, 2 cores shared with another build: timings are noisy.
# Run from the repository root: sh results/llvmpipe/hash_grid/run.sh
set -u
P=./target/release/photonmap
D=results/llvmpipe/hash_grid
T=${TMPDIR:-/tmp}/hash_grid_images
mkdir -p "$T"
case_run() { # name scene grid(uniform|hash) [--set ...]
  name=$1; scene=$2; grid=$3; shift 3
  # photons takes no image size: drop --width N and --height N for it.
  ph=""; skip=0
  for a in "$@"; do
    if [ $skip = 1 ]; then skip=0; continue; fi
    case "$a" in --width|--height) skip=1 ;; *) ph="$ph $a" ;; esac
  done
  $P photons "$scene" --grid "$grid" --json $ph > "$D/$name.$grid.photons.json" 2> "$D/$name.$grid.photons.err"
  [ "${PHOTONS_ONLY:-0}" = 1 ] && return
  $P render "$scene" --grid "$grid" --quiet --json -o "$T/$name.$grid.exr" "$@" > "$D/$name.$grid.render.json" 2> "$D/$name.$grid.render.err"
  if [ -f "reference_images/$scene.sppm.exr" ] && [ -f "$T/$name.$grid.exr" ]; then
    $P compare "$T/$name.$grid.exr" "reference_images/$scene.sppm.exr" --json > "$D/$name.$grid.compare.json" 2> "$D/$name.$grid.compare.err"
  fi
}
# 1. GLASS BALL, its own grid (250 x 1 x 250 over the floor).
# Every render at the SPPM references' size (--scale 2 of the scene's).
G="--width 256 --height 192"
case_run glass_ball_scene_grid glass_ball uniform $G
case_run glass_ball_scene_grid glass_ball hash $G
# 2. GLASS BALL, the whole scene box at fine cells (256 x 150 x 256 = 9.8M cells).
FINE="--set photon_map.grid_min=[-3.0,0.0,-3.0] --set photon_map.grid_max=[3.0,3.5,3.0] --set photon_map.grid_resolution=[256,150,256] $G"
case_run glass_ball_fine glass_ball uniform $FINE
case_run glass_ball_fine glass_ball hash $FINE
# 3. CORNELL BOX at 1024^3 over its box: uniform is refused; hashed renders with
#    max_radius 0.02 (10 cells), set beside the same render on the scene's own grid.
C1024="--set photon_map.grid_resolution=[1024,1024,1024] --set photon_map.max_radius=0.02 --width 256 --height 256"
case_run cornell_1024 cornell_box uniform $C1024
case_run cornell_1024 cornell_box hash $C1024
case_run cornell_own_r002 cornell_box uniform --set photon_map.max_radius=0.02 --width 256 --height 256
case_run cornell_own cornell_box uniform --width 256 --height 256
# 4. A mesh scene with empty space: the OBJ Cornell box (about 550 units a side)
#    with a 256^3 grid fitted to its photons, max_radius 8 (about 4 cells).
M256="--set photon_map.grid_resolution=[256,256,256] --set photon_map.max_radius=8.0 --width 128 --height 96"
case_run cornell_obj_256 cornell_box_obj uniform $M256
case_run cornell_obj_256 cornell_box_obj hash $M256
# 5. Stencil routing (m = 4), photons only: grid texels and the power a hashed
#    routing loses (cells whose full bucket kept none of their photons).
for g in uniform hash; do
  $P photons glass_ball --build stencil --grid $g --json > "$D/stencil_glass_ball.$g.photons.json"
  $P photons cornell_box --build stencil --grid $g --json > "$D/stencil_cornell.$g.photons.json"
done
$P photons cornell_box --build stencil --grid hash --hash-buckets 4096 --json > "$D/stencil_cornell_4096.hash.photons.json"
$P photons cornell_box --build stencil --grid hash --json --set 'photon_map.grid_resolution=[1024,1024,1024]' > "$D/stencil_cornell_1024.hash.photons.json"
