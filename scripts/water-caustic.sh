#!/usr/bin/env bash
# Bitterli's water caustic against its Tungsten reference
# (docs/src/evaluation/import-trial.md): a Cornell box filled with water
# (eta 1.8) under a wavy surface; the camera sees most of the box through
# the water. Renders photonmap's SPPM at its defaults and Mitsuba 3's path
# and light tracers for 60 s each at 256 x 256 (bench mitsuba), scores
# them by region against the reference averaged over 4 x 4 blocks (the
# light's block left out: the half-float file clips it), then probes the
# reference's path depth: SPPM with its photons' bounces capped at 7 and
# 8, Mitsuba's light tracer at max_depth 9 (8 bounces, the file's
# `maxdepth` 9 less one), and SPPM for 240 s.
#
#   scripts/water-caustic.sh WATER PY [OUT]
#
# WATER: gonsolo/bitterli's water-caustic/pbrt folder (scene-v4.pbrt,
# models/, TungstenRender.exr); PY: a Python with `mitsuba` and numpy
# (DRJIT_LIBLLVM_PATH naming libLLVM 16 or newer where the system's is
# older); OUT: default results/llvmpipe/import_trial/water_caustic.
set -euo pipefail
WATER=$(realpath "$1"); PY=$2
OUT=$(realpath -m "${3:-results/llvmpipe/import_trial/water_caustic}")
PM=$(realpath "${PHOTONMAP:-target/release/photonmap}")
HERE=$(realpath "$(dirname "$0")")
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
mkdir -p "$OUT"
# The scene is read from a copy of its folder's layout in WORK, so that
# every path the tables record is relative.
ln -s "$WATER/scene-v4.pbrt" "$WORK/scene-v4.pbrt"
ln -s "$WATER/models" "$WORK/models"
cd "$WORK"
"$PY" "$HERE/downsample-reference.py" "$WATER/TungstenRender.exr" 4 reference.exr mask.png 508:512:82:84
"$PM" convert reference.exr "$OUT/reference.png"
cp mask.png "$OUT/mask.png"
REGIONS=(--region "ceiling=40:216:2:28" --region "back wall above the water=40:216:34:44"
    --region "back wall under the water=50:200:95:150" --region "floor under the water=96:160:238:250"
    --region "left wall under the water=4:16:95:215")
"$PM" bench mitsuba --scene scene-v4.pbrt --reference reference.exr --mask mask.png \
    "${REGIONS[@]}" --seconds 60 --python "$PY" --out defaults --quiet
cp defaults/{table.md,regions.md,mitsuba.json,convergence.svg} "$OUT/"
cp defaults/{photonmap_sppm_60s,mitsuba_path_60s,mitsuba_ptracer_60s}.png "$OUT/"
"$PM" bench mitsuba --scene scene-v4.pbrt --reference reference.exr --mask mask.png \
    "${REGIONS[@]}" --seconds 60 --integrators ptracer --max-depth 9 --python "$PY" \
    --out ptracer_d9 --quiet
probe() { # LABEL RENDER-FLAGS...
    local label=$1; shift
    "$PM" render scene-v4.pbrt --method sppm --width 256 --height 256 "$@" --quiet \
        --exr "$label.exr"
    "$PM" compare "$label.exr" reference.exr --mask mask.png "${REGIONS[@]}" --json > "$label.json"
}
probe bounces7 --time 60 --photon-bounces 7
probe bounces8 --time 60 --photon-bounces 8
probe sppm240 --time 240
"$PY" - "$WORK" "$OUT/depth.md" <<'PYEOF'
import json, re, sys
work, out = sys.argv[1], sys.argv[2]
rows = []
def bench_row(path, name):
    text = open(path).read()
    for line in text.splitlines():
        if line.startswith(f"| {name} |"):
            return [c.strip() for c in line.strip("|").split("|")][2:]
    raise SystemExit(f"{path}: no row {name}")
heads = [c.strip() for c in open(f"{work}/defaults/regions.md").read().splitlines()[4].strip("|").split("|")][2:]
rows.append(("photonmap SPPM, defaults (32 photon bounces), 60 s", bench_row(f"{work}/defaults/regions.md", "photonmap SPPM")))
for label, name in [("bounces7", "photonmap SPPM, photon bounces 7, 60 s"), ("bounces8", "photonmap SPPM, photon bounces 8, 60 s"), ("sppm240", "photonmap SPPM, defaults, 240 s")]:
    v = json.load(open(f"{work}/{label}.json"))
    rows.append((name, [f"{r['energy']:.3f}" for r in v["regions"]]))
rows.append(("Mitsuba ptracer, unbounded, 60 s", bench_row(f"{work}/defaults/regions.md", "Mitsuba ptracer")))
rows.append(("Mitsuba ptracer, max_depth 9 (8 bounces), 60 s", bench_row(f"{work}/ptracer_d9/regions.md", "Mitsuba ptracer")))
with open(out, "w") as f:
    f.write("`scripts/water-caustic.sh WATER PY`: each region's energy (the image's mean there over the Tungsten reference's, within the mask); "
            "the SPPM probes are `photonmap render scene-v4.pbrt --method sppm --width 256 --height 256 [FLAGS]`, scored by "
            "`photonmap compare IMAGE reference.exr --mask mask.png --region ... --json`; Mitsuba's light tracer cannot see through the water (0).\n\n")
    f.write("| run | " + " | ".join(heads) + " |\n|---|" + "---|" * len(heads) + "\n")
    for name, cells in rows:
        f.write(f"| {name} | " + " | ".join(cells) + " |\n")
print(open(out).read())
PYEOF
