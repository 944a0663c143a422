#!/usr/bin/env bash
# Whether a change leaves the paper scenes as they were: GLASS BALL, RING and
# CORNELL BOX at half size, seed 7, by the paper's method, SPPM (16
# iterations) and final gather (16 rays; not RING, which has no diffuse
# interreflection), each rendered by two builds and compared with
# `photonmap compare`. Writes a Markdown table headed by its command.
#
#   scripts/paper-scenes-unchanged.sh BEFORE_BIN AFTER_BIN WORK OUT.md
#
# BEFORE_BIN, AFTER_BIN: two photonmap binaries (e.g. one built from the
# commit before the change); WORK: where the EXRs go.
set -euo pipefail
BEFORE=$(realpath "$1"); AFTER=$(realpath "$2"); WORK=$(realpath -m "$3"); OUT=$4
mkdir -p "$WORK/before" "$WORK/after"
runs=()
for spec in "glass_ball 256 192" "ring 256 192" "cornell_box 256 256"; do
    set -- $spec
    for method in paper sppm gather; do
        [ "$1" = ring ] && [ "$method" = gather ] && continue
        runs+=("$1 $2 $3 $method")
    done
done
flags() { # METHOD
    case $1 in
        paper) ;;
        sppm) echo "--method sppm --iterations 16" ;;
        gather) echo "--final-gather 16" ;;
    esac
}
{
    echo "\`scripts/paper-scenes-unchanged.sh BEFORE AFTER WORK OUT.md\`: each row \`photonmap render SCENE --width W --height H --seed 7 [METHOD FLAGS] --exr X\` by both builds, then \`photonmap compare AFTER.exr BEFORE.exr --json\`."
    echo
    echo "| scene | method | size | relative RMSE | energy |"
    echo "|---|---|---|---|---|"
    for run in "${runs[@]}"; do
        set -- $run
        name="$1_$4"
        for side in before after; do
            bin=$BEFORE; [ $side = after ] && bin=$AFTER
            # shellcheck disable=SC2046
            "$bin" render "$1" --width "$2" --height "$3" --seed 7 $(flags "$4") \
                --quiet --exr "$WORK/$side/$name.exr"
        done
        "$AFTER" compare "$WORK/after/$name.exr" "$WORK/before/$name.exr" --json \
            --diff "$WORK/$name.diff.png" |
            python3 -c "import json, sys; v = json.load(sys.stdin); print(f\"| $1 | $4 | $2 x $3 | {v['rel_rmse']:.2e} | {v['energy']:.9f} |\")"
    done
} > "$OUT"
cat "$OUT"
